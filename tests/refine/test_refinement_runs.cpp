// Refinement over whole runs (docs/theory.md §13): momentum through dozens of events, damage
// kept current through steps, events and compactions (§8), and the 3D split.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/physics/bond_loops.hpp"
#include "refine/refiner.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::all_particles;
using test::Box;
using test::plate;

TEST(Refinement, MomentumAndDamageThroughAnAdaptiveRun) {
  // The pre-cracked plate under equal and opposite tractions (zero net external force): dozens of
  // events while the crack runs must keep the momentum at round-off of Σ m |v|, and the damage
  // the stepper and the events keep current must equal a full pass over the bonds, bit for bit.
  const auto s = test::pulled_cracked_plate(1e-3);
  Simulation sim(s);
  refine::Settings set;
  set.trigger.damage = 0.02;
  set.check_every = 5;
  set.mapping = refine::StateMapping::Linear;
  refine::Refiner refiner(set);
  int events = 0, damage_checks = 0;
  double worst = 0.0;
  for (int k = 1; k <= 300; ++k) {
    sim.step();
    if (refiner.due(k) && refiner.check(sim).parents > 0) ++events;
    if (k % 10 == 0 || k % 5 == 1) {  // before and after an event's step
      auto full = sim.particles();
      compute_damage(sim.bonds(), full, sim.setup().partial_volume);
      ASSERT_EQ(full.damage, sim.particles().damage) << "step " << k;
      ++damage_checks;
    }
    if (k % 20 == 0) worst = std::max(worst, test::relative_momentum(sim));
  }
  std::printf("adaptive run: %d events, %zu particles, worst |P|/sum m|v| %.2e\n", events,
              sim.particles().size(), worst);
  EXPECT_GE(events, 12);
  EXPECT_LT(worst, 1e-13);
  EXPECT_GT(*std::max_element(sim.particles().damage.begin(), sim.particles().damage.end()), 0.3);
  EXPECT_GT(damage_checks, 60);
}

TEST(Refinement, ThreeDimensionalSplitConservesAndRefineAllEqualsFine) {
  auto cube = [](double dx) {
    SimulationSetup s;
    s.section = {3, PlaneMode::Stress, 1.0, 1.0};
    s.materials = {{72e9, 2440, 135.0}};
    s.partial_volume = PartialVolume::Linear;
    s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.006, 0.006, 0.006}}, dx, 0}}, 3);
    InitialCondition ic;
    ic.region = Box{{0, 0, 0}, {0.006, 0.006, 0.006}};
    ic.velocity = geometry::Vec3{1.0, -0.5, 0.25};
    s.initial_conditions = {ic};
    BoundaryCondition fixed;
    fixed.region = Box{{0, 0, 0}, {0.001, 0.006, 0.006}};
    s.boundary_conditions = {fixed};
    return s;
  };
  auto fine_setup = cube(0.5e-3);
  const double dt = 0.5 * Simulation(fine_setup).critical_dt();
  fine_setup.fixed_dt = dt;
  auto coarse_setup = cube(1e-3);
  coarse_setup.fixed_dt = dt;
  Simulation fine(fine_setup), coarse(coarse_setup);
  const auto before = coarse.energies();
  const auto ev = refine::split(coarse, all_particles(coarse));
  const auto after = coarse.energies();
  EXPECT_EQ(ev.children, 8 * 216u);
  EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(after.momentum[a], before.momentum[a], 1e-12 * std::abs(before.momentum[0]));
  ASSERT_EQ(coarse.particles().size(), fine.particles().size());
  EXPECT_EQ(coarse.bonds().bond_count(), fine.bonds().bond_count());
  coarse.run_steps(50);
  fine.run_steps(50);
  const auto ec = coarse.energies(), ef = fine.energies();
  EXPECT_NEAR(ec.kinetic, ef.kinetic, 1e-9 * ef.kinetic);
  EXPECT_NEAR(ec.strain, ef.strain, 1e-9 * ef.strain);
}

}  // namespace
}  // namespace dhpd
