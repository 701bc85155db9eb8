// Engine contracts: a bond uses its owner's material (CMAME 2017 §5), the time loop never
// allocates, and an unstable run is detected instead of silently producing NaN.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "engine/base/errors.hpp"
#include "tests/support/engine.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
}  // namespace

// Counting replacement of the global allocator for this test binary (test-only code). GCC 12
// flags free() on memory from the (replaced) operator new once both are inlined; here they
// are a matched pair by construction.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
void* counted_allocation(std::size_t n) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return std::malloc(n ? n : 1);
}
}  // namespace

// Every plain and nothrow form is replaced, so each allocation pairs with a matching release.
void* operator new(std::size_t n) {
  if (void* p = counted_allocation(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = counted_allocation(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return counted_allocation(n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return counted_allocation(n);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace dhpd {
namespace {

SimulationSetup two_material_bar() {
  SimulationSetup s;
  s.section = {1, PlaneMode::Stress, 1, 1e-4};
  s.materials = {{1e9, 1000, 1.0}, {7e9, 3000, 2.0}};
  using geometry::Box;
  s.points = geometry::fill_lattice(
      {{Box{{0, 0, 0}, {0.05, 0, 0}}, 1e-3, 0}, {Box{{0.05, 0, 0}, {0.1, 0, 0}}, 2e-3, 1}}, 1);
  s.partial_volume = PartialVolume::Linear;
  return s;
}

TEST(MultipleMaterials, EachBondUsesItsOwnersMaterialInBothViews) {
  const Simulation sim(two_material_bar());
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  const auto rule = sim.setup().partial_volume;
  std::size_t mixed = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      if (!b.has_own(k)) continue;
      const auto j = static_cast<std::size_t>(b.other[k]);
      const auto& own = sim.setup().materials[static_cast<std::size_t>(p.material[i])];
      const double C = micromodulus(own, sim.setup().section, p.horizon[i]);
      const double K = C * bond_weight(p, rule, i, j, b.length(k)) * b.own_factor(k);
      const auto in_j = b.find(j, static_cast<std::int32_t>(i));
      ASSERT_GE(in_j, 0);
      // Row i's entry holds this bond and the reverse one (owned by j, with j's material); row
      // j's entry holds the same two with the same stiffness bits.
      EXPECT_TRUE(b.has_dual(in_j));
      EXPECT_EQ(b.has_dual(k), b.has_own(in_j));  // no reverse bond: i outside j's smaller horizon
      const auto& theirs = sim.setup().materials[static_cast<std::size_t>(p.material[j])];
      const double K_rev = !b.has_dual(k)
                               ? 0.0
                               : micromodulus(theirs, sim.setup().section, p.horizon[j]) *
                                     bond_weight(p, rule, j, i, b.length(k)) * b.own_factor(in_j);
      const double stored = static_cast<double>(b.stiffness[k]) * b.stiffness_scale;
      EXPECT_NEAR(stored, K + K_rev, 6e-8 * (K + K_rev));  // single precision
      EXPECT_EQ(b.stiffness[k], b.stiffness[in_j]);
      EXPECT_EQ(sim.critical_stretch()[i],
                critical_stretch(own, sim.setup().section, p.horizon[i]));
      mixed += p.material[i] != p.material[j];
    }
  EXPECT_GT(mixed, 0u);  // the bar really has bonds across the interface
}

/// The two-material bar with a velocity pulse and a pulled end: bonds break within 200 steps.
SimulationSetup breaking_bar() {
  auto s = two_material_bar();
  s.effects.fracture = true;
  InitialCondition ic;
  ic.region = geometry::Box{{0, 0, 0}, {0.1, 0, 0}};
  ic.velocity = Vec3{1.0, 0, 0};
  ic.gaussian_width = 0.01;
  ic.gaussian_center = {0.05, 0, 0};
  s.initial_conditions = {ic};
  BoundaryCondition bc;
  bc.kind = BoundaryCondition::Kind::Velocity;
  bc.region = geometry::Box{{0, 0, 0}, {0.003, 0, 0}};
  bc.velocity[0] = -0.5;
  s.boundary_conditions = {bc};
  return s;
}

TEST(TimeLoop, StepsDoNotAllocate) {
  Simulation sim(breaking_bar());
  sim.run_steps(5);  // warm up the thread team
  sim.step({.strain_energy = true});
  g_allocations = 0;
  g_counting = true;
  for (int k = 0; k < 200; ++k) sim.step({.strain_energy = k % 10 == 0});
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
}

// A step asked for its strain energy gives energies() the bits of a pass over the rows after it,
// while bonds break; a step that was not asked leaves energies() to that pass.
TEST(TimeLoop, StrainEnergyFromTheStepEqualsAPassAfterIt) {
  Simulation fused(breaking_bar()), plain(breaking_bar());
  for (int k = 1; k <= 200; ++k) {
    fused.step({.strain_energy = k % 3 == 0});
    plain.step();
    ASSERT_EQ(fused.strain_energy_from_step(), k % 3 == 0);
    ASSERT_FALSE(plain.strain_energy_from_step());
    const auto e = fused.energies();
    ASSERT_EQ(e.strain, plain.energies().strain) << "step " << k;
    ASSERT_EQ(e.strain, strain_energy_total(fused.bonds(), fused.particles()));
  }
  EXPECT_GT(fused.broken_bonds(), 0);
  EXPECT_EQ(fused.broken_bonds(), plain.broken_bonds());
}

TEST(Stability, BlowUpIsDetected) {
  auto s = two_material_bar();
  InitialCondition ic;
  ic.region = geometry::Box{{0, 0, 0}, {0.1, 0, 0}};
  ic.velocity = Vec3{1.0, 0, 0};
  ic.gaussian_width = 0.005;
  ic.gaussian_center = {0.05, 0, 0};
  s.initial_conditions = {ic};
  {
    Simulation stable(s);
    stable.run_steps(300);
    EXPECT_NO_THROW(stable.check_stable(stable.energies()));
  }
  Simulation probe(s);
  s.fixed_dt = 1.5 * probe.critical_dt();  // beyond the Verlet limit: modes grow every step
  Simulation sim(s);
  EXPECT_FALSE(sim.dt_is_stable());
  bool caught = false;
  std::int64_t steps = 0;
  try {  // the guard in step() stops it within a few steps
    for (; steps < 2000; ++steps) sim.step();
  } catch (const InstabilityError& e) {
    caught = true;
    EXPECT_NE(std::string(e.what()).find("1.5 x the stable step"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(caught);
  EXPECT_LT(steps, 50);
}

}  // namespace
}  // namespace dhpd
