// The state mapping of a refinement event (issue 12; docs/scenes.md `mapping`): linear fields are
// reproduced at every child and momentum is exact; a strained body is refined without breaking a
// bond; a bond the mapped state stretches to s0 starts broken and is counted; loads follow the
// parents.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/physics/bond_law.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "tests/support/refine.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using geometry::Vec3;
using test::all_particles;
using test::Box;
using test::plate;

/// w(X) = w0 + A X (+ ½ XᵀH_r X per component when `curved`), the fields of these tests.
struct Field {
  double w0[2], A[2][2], H[2][3];  // H per component: xx, yy, xy
  bool curved = false;
  double at(int r, const Vec3& x) const {
    double w = w0[r] + A[r][0] * x[0] + A[r][1] * x[1];
    if (curved)
      w += 0.5 * H[r][0] * x[0] * x[0] + 0.5 * H[r][1] * x[1] * x[1] + H[r][2] * x[0] * x[1];
    return w;
  }
};

const Field kDisplacement{
    {1e-6, -2e-6}, {{1e-3, 4e-4}, {-3e-4, 2e-3}}, {{2.0, -1.0, 0.5}, {1.0, 3.0, -2.0}}};
const Field kVelocity{
    {3.0, -1.0}, {{30.0, -12.0}, {8.0, 20.0}}, {{4e3, 1e3, -2e3}, {-1e3, 5e3, 3e3}}};

void impose(Simulation& sim, Field u, Field v) {
  auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto x = point_of(p.reference_position, i);
    for (int a = 0; a < 2; ++a) {
      p.displacement[a][i] = u.at(a, x);
      p.velocity[a][i] = v.at(a, x);
      p.position[a][i] = x[a] + p.displacement[a][i];
    }
  }
}

struct Worst {
  double u = 0, v = 0;
};

/// Largest distance of the children's u (all) and v (those of parents that kept every child)
/// from the fields.
Worst off_field(const Simulation& sim, const ParticleStore& before, const Field& u,
                const Field& v) {
  const auto& p = sim.particles();
  const auto ev = test::family_of_event(before, p);
  std::vector<int> siblings(p.size(), 0);
  for (const auto q : ev.parent_slot) ++siblings[static_cast<std::size_t>(q)];
  Worst w;
  for (std::size_t c = 0; c < ev.child_slot.size(); ++c) {
    const auto k = static_cast<std::size_t>(ev.child_slot[c]);
    const auto x = point_of(p.reference_position, k);
    for (int a = 0; a < 2; ++a) {
      w.u = std::max(w.u, std::abs(p.displacement[a][k] - u.at(a, x)));
      if (siblings[static_cast<std::size_t>(ev.parent_slot[c])] == 4)
        w.v = std::max(w.v, std::abs(p.velocity[a][k] - v.at(a, x)));
    }
  }
  return w;
}

/// A disc with a pre-crack into it: cells on the rim and along the crack drop children.
SimulationSetup cracked_disc() {
  const auto disc = geometry::Shape::ball({0.01, 0.01, 0}, 0.0093);
  auto s = test::plate(1e-3, 0.02, 0.02);
  s.points = geometry::fill_lattice({{disc, 1e-3, 0}}, 2);
  s.body = disc;
  s.cracks = {{{{0.0, 0.0104, 0}, {0.012, 0.0104, 0}}}};
  s.resort_fraction = 0.0;  // keep the event's slots valid for off_field
  return s;
}

TEST(RefinementMapping, LinearFieldsAreReproducedAndMomentumIsExact) {
  for (const auto mapping : {refine::StateMapping::Linear, refine::StateMapping::Quadratic,
                             refine::StateMapping::Copy}) {
    Simulation sim(cracked_disc());
    impose(sim, kDisplacement, kVelocity);
    const auto before = sim.energies();
    const auto store = sim.particles();
    const auto ev = refine::split(sim, all_particles(sim), mapping);
    const auto after = sim.energies();
    const auto w = off_field(sim, store, kDisplacement, kVelocity);
    const double pscale = std::hypot(before.momentum[0], before.momentum[1]);
    std::printf(
        "linear field, %s: %zu children (%zu dropped), worst |u - u(X)| %.2e m, "
        "|v - v(X)| %.2e m/s, momentum %.1e %.1e\n",
        refine::mapping_name(mapping), ev.children, ev.dropped, w.u, w.v,
        (after.momentum[0] - before.momentum[0]) / pscale,
        (after.momentum[1] - before.momentum[1]) / pscale);
    ASSERT_GT(ev.dropped, 0u);
    for (int a = 0; a < 2; ++a) EXPECT_NEAR(after.momentum[a], before.momentum[a], 1e-13 * pscale);
    if (mapping == refine::StateMapping::Copy) {
      EXPECT_GT(w.u, 1e-7);  // a quarter cell times the gradient: what the copy misses
      continue;
    }
    EXPECT_LT(w.u, 1e-17);
    EXPECT_LT(w.v, 1e-12);
  }
}

TEST(RefinementMapping, QuadraticMappingReproducesACurvedField) {
  Field u = kDisplacement, v = kVelocity;
  u.curved = v.curved = true;
  for (const auto mapping : {refine::StateMapping::Quadratic, refine::StateMapping::Linear}) {
    auto s = test::plate(1e-3, 0.02, 0.02);
    s.resort_fraction = 0.0;
    Simulation sim(s);
    impose(sim, u, v);
    const auto store = sim.particles();
    refine::split(sim, all_particles(sim), mapping);
    const auto w = off_field(sim, store, u, v);
    std::printf("curved field, %s: worst |u - u(X)| %.2e m\n", refine::mapping_name(mapping), w.u);
    if (mapping == refine::StateMapping::Quadratic) {
      EXPECT_LT(w.u, 1e-17);
    } else {
      EXPECT_GT(w.u, 1e-10);
    }
  }
}

/// The glass plate at isotropic strain ε (every bond stretched by ε exactly), fracture on.
SimulationSetup strained_plate(double eps) {
  auto s = test::plate(1e-3, 0.03, 0.03);
  s.effects.fracture = true;
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.03, 0.03, 0}};
  ic.strain = Vec3{eps, eps, 0};
  s.initial_conditions = {ic};
  return s;
}

/// The particles of the central 10 mm × 10 mm patch.
std::vector<std::int32_t> patch(const Simulation& sim) {
  std::vector<std::int32_t> out;
  const Box box{{0.01, 0.01, 0}, {0.02, 0.02, 0}};
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (box.contains(point_of(p.reference_position, i), 2)) out.push_back(static_cast<int>(i));
  return out;
}

/// Largest stretch over intact bonds of owners that may fail, relative to the owner's s0.
double worst_intact_stretch(const Simulation& sim) {
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      if (b.own_intact(k) && !p.no_fail[i])
        worst = std::max(worst, bond_law::stretch(bond_law::squared_length(
                                                      p, i, static_cast<std::size_t>(b.other[k])),
                                                  b.length(k)) /
                                    sim.critical_stretch()[i]);
  return worst;
}

TEST(RefinementMapping, AStrainedBodyIsRefinedWithoutBreakingABond) {
  // Every bond at 0.9 s0 of the coarse level (the smaller s0: the children's is √2 larger).
  const double s0 = Simulation(test::plate(1e-3, 0.03, 0.03)).critical_stretch()[0];
  for (const auto mapping : {refine::StateMapping::Linear, refine::StateMapping::Quadratic,
                             refine::StateMapping::Copy}) {
    Simulation sim(strained_plate(0.9 * s0));
    const auto ev = refine::split(sim, patch(sim), mapping);
    const double worst = worst_intact_stretch(sim);
    std::printf(
        "strained at 0.9 s0, %s: event broke %lld (no healing) + %lld (overstretched), "
        "worst intact stretch %.3f s0\n",
        refine::mapping_name(mapping), static_cast<long long>(ev.started_broken),
        static_cast<long long>(ev.started_overstretched), worst);
    EXPECT_EQ(ev.started_broken, 0);
    EXPECT_LT(worst, 1.0);  // the birth rule leaves no intact bond at or above s0
    if (mapping == refine::StateMapping::Copy) {
      EXPECT_GT(ev.started_overstretched, 0);  // the copy's jumps double the stretch
    } else {
      EXPECT_EQ(ev.started_overstretched, 0);
      EXPECT_LE(worst, 0.9 * (1 + 1e-9));
    }
  }
}

TEST(RefinementMapping, TheNextFiftyStepsBreakNoMoreBondsThanWithoutTheEvent) {
  // After the event the body must stay as close to equilibrium as it was. The papers' DH-PD puts
  // a force layer on a level interface under a uniform strain (the children's dual horizons do
  // not cover the coarse side; docs/theory.md §14), and, created suddenly, it breaks bonds from
  // about 0.5 s0 on; the interface correction removes that layer.
  const double s0 = Simulation(test::plate(1e-3, 0.03, 0.03)).critical_stretch()[0];
  for (const bool correction : {true, false}) {
    auto s = strained_plate(0.9 * s0);
    s.interface_correction = correction;
    Simulation unrefined(s), sim(s);
    const auto ev = refine::split(sim, patch(sim));
    unrefined.run_steps(50);
    sim.run_steps(50);
    std::printf(
        "strained at 0.9 s0, interface correction %s (factors %.2f to %.2f): after 50 "
        "steps %lld bonds broken refined, %lld unrefined\n",
        correction ? "on" : "off", ev.interfaces.smallest, ev.interfaces.largest,
        static_cast<long long>(sim.broken_bonds()),
        static_cast<long long>(unrefined.broken_bonds()));
    if (correction) {
      EXPECT_LE(sim.broken_bonds(), unrefined.broken_bonds());
    } else {
      EXPECT_GT(sim.broken_bonds(), 2 * unrefined.broken_bonds());  // what the correction fixes
    }
  }
}

TEST(RefinementMapping, AtNinetyPercentOfTheFineCriticalStretchChildrenStayIntact) {
  // 0.9 s0 of the finer level is above the coarse s0, so the coarse particles outside the patch
  // are held unbreakable; the children are not.
  const double s0_fine = Simulation(test::plate(0.5e-3, 0.03, 0.03)).critical_stretch()[0];
  for (const double ratio : {0.9, 1.05}) {
    auto s = strained_plate(ratio * s0_fine);
    s.no_fail = {Box{{0, 0, 0}, {0.03, 0.0099, 0}}, Box{{0, 0.0201, 0}, {0.03, 0.03, 0}},
                 Box{{0, 0, 0}, {0.0099, 0.03, 0}}, Box{{0.0201, 0, 0}, {0.03, 0.03, 0}}};
    Simulation sim(s);
    const auto ev = refine::split(sim, patch(sim));
    std::size_t child_bonds = 0;
    const auto& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.level[i] == 1 && !p.no_fail[i]) child_bonds += sim.bonds().own_count(i);
    std::printf(
        "strained at %.2f s0 of the fine level: %lld of %zu children's bonds started "
        "overstretched\n",
        ratio, static_cast<long long>(ev.started_overstretched), child_bonds);
    EXPECT_LT(worst_intact_stretch(sim), 1.0);
    if (ratio < 1.0) {
      EXPECT_EQ(ev.started_overstretched, 0);
    } else {  // the physics puts every child bond above s0: each starts broken, counted
      EXPECT_EQ(static_cast<std::size_t>(ev.started_overstretched), child_bonds);
    }
  }
}

/// The plate with a traction on [8.7, 10] mm (the coarse row at 9.5 mm only: depth 1 mm; the
/// children of the row at 8.5 mm include one at 8.75 mm, inside the region) or a velocity held
/// on [0, 1.7] mm (rows 0.5 and 1.5 mm; their children at 1.75 mm lie outside the region).
SimulationSetup plate_with(BoundaryCondition::Kind kind) {
  auto s = test::plate(1e-3, 0.02, 0.01);
  BoundaryCondition bc;
  bc.kind = kind;
  if (kind == BoundaryCondition::Kind::Traction) {
    bc.region = Box{{0, 0.0087, 0}, {0.02, 0.01, 0}};
    bc.traction = {0, 5e6, 0};
    bc.normal_axis = 1;
  } else {
    bc.region = Box{{0, 0, 0}, {0.0017, 0.01, 0}};
    bc.velocity[0] = 1.0;
  }
  s.boundary_conditions = {bc};
  return s;
}

TEST(RefinementMapping, LoadsFollowTheParentsNotTheRegions) {
  // Traction: from rest, one step gives Σ m v = dt Σ b V (internal forces cancel exactly).
  std::vector<double> force, held;
  for (const bool refined : {false, true}) {
    Simulation pulled(plate_with(BoundaryCondition::Kind::Traction));
    if (refined) refine::split(pulled, all_particles(pulled));
    pulled.step();
    force.push_back(pulled.energies().momentum[1] / pulled.dt());
    Simulation pushed(plate_with(BoundaryCondition::Kind::Velocity));
    if (refined) refine::split(pushed, all_particles(pushed));
    pushed.step();
    const auto& p = pushed.particles();
    double v = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) v += p.velocity[0][i] == 1.0 ? p.volume[i] : 0.0;
    held.push_back(v);
  }
  std::printf("traction force %.6e N -> %.6e N after refining; held volume %.3e -> %.3e m^3\n",
              force[0], force[1], held[0], held[1]);
  EXPECT_NEAR(force[0], 5e6 * 0.02 * 1e-3, 1e-9 * force[0]);  // t × edge length × thickness
  EXPECT_NEAR(force[1], force[0], 1e-9 * force[0]);
  EXPECT_NEAR(held[0], 2 * 10 * 1e-9, 1e-20);
  EXPECT_NEAR(held[1], held[0], 1e-9 * held[0]);
}

TEST(Refinement, LinearMappingPutsChildrenOnAUniformStrainField) {
  // u = ε (X − o): the linear mapping reproduces it at every child (the copy does not), and both
  // conserve momentum and kinetic energy because velocities are copied.
  for (const auto mapping : {refine::StateMapping::Copy, refine::StateMapping::Linear}) {
    auto s = plate(1e-3, 0.02, 0.01);
    InitialCondition ic;
    ic.region = Box{{0, 0, 0}, {0.02, 0.01, 0}};
    ic.strain = geometry::Vec3{1e-3, -4e-4, 0};
    ic.origin = {0.01, 0.005, 0};
    ic.velocity = geometry::Vec3{1.0, 2.0, 0};
    s.initial_conditions = {ic};
    Simulation sim(s);
    const auto before = sim.energies();
    const auto ev = refine::split(sim, all_particles(sim), mapping);
    const auto after = sim.energies();
    EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic);
    double worst = 0.0;
    const auto& p = sim.particles();
    for (std::size_t k = p.size() - ev.children; k < p.size(); ++k)
      for (int a = 0; a < 2; ++a) {
        const double exact = (*ic.strain)[a] * (p.reference_position[a][k] - ic.origin[a]);
        worst = std::max(worst, std::abs(p.displacement[a][k] - exact));
      }
    if (mapping == refine::StateMapping::Linear) {
      EXPECT_LT(worst, 1e-15);
    } else {
      EXPECT_NEAR(worst, 0.25e-3 * 1e-3, 1e-12);  // a quarter cell times the largest strain
    }
  }
}

}  // namespace
}  // namespace dhpd
