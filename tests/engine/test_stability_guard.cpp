// The instability guard (engine/physics/stability_guard.*): velocity Verlet's shadow energy is
// conserved by stable runs, and created energy and blow-ups stop the run with the step, time,
// particles and cause (refinement's mapping energy: tests/refine/test_guard_mapping.cpp; input
// refused at load time: tests/cli/test_cli_guard.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "engine/base/errors.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::pulsed_plate;

double shadow(const Energies& e) {
  return e.kinetic + e.strain - e.verlet_correction;
}

TEST(Guard, ShadowEnergyIsConservedWherePlainEnergySwings) {
  for (const double safety : {0.5, 0.8, 0.95}) {
    Simulation sim(pulsed_plate(safety));
    const auto e0 = sim.energies();
    double plain_swing = 0.0, shadow_drift = 0.0;
    for (int k = 0; k < 400; ++k) {
      sim.step();
      const auto e = sim.energies();
      plain_swing = std::max(plain_swing, std::abs(e.kinetic + e.strain - e0.kinetic) / e0.kinetic);
      shadow_drift = std::max(shadow_drift, std::abs(shadow(e) - shadow(e0)) / e0.kinetic);
      sim.check_stable(e);
    }
    EXPECT_LT(shadow_drift, 1e-6) << "safety " << safety;  // measured 2.3e-9 to 2.5e-8
    if (safety >= 0.8) {
      EXPECT_GT(plain_swing, 10.0 * shadow_drift) << "safety " << safety;
    }
  }
}

TEST(Guard, CreatedEnergyStopsTheRunNamingTheParticle) {
  for (const double added : {0.003, 0.03}) {  // 0.3 % passes, 3 % is caught (tolerance 1 %)
    Simulation sim(pulsed_plate(0.8));
    sim.run_steps(50);
    auto& p = sim.particles();
    const auto before = sim.energies();
    // A fault that puts energy into one particle: raise its speed.
    const std::size_t i = p.size() / 3;
    const double m = p.density[i] * p.volume[i];
    const double v = std::sqrt(2.0 * added * before.kinetic / m);
    p.velocity[1][i] += v;
    sim.run_steps(10);
    if (added < 0.01) {
      EXPECT_NO_THROW(sim.check_stable(sim.energies()));
      continue;
    }
    try {
      sim.check_stable(sim.energies());
      ADD_FAILURE() << "3 % of created energy was not caught";
    } catch (const InstabilityError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("shadow energy"), std::string::npos) << what;
      EXPECT_NE(what.find("step 60"), std::string::npos) << what;
      EXPECT_NE(what.find("likely cause"), std::string::npos) << what;
    }
  }
}

/// A 1D bar of two materials (two spacings) with a velocity pulse: the stable-step estimate
/// (docs/theory.md §9) is tight in 1D, so 1.5 x it is unstable (in 2D the estimate is conservative
/// by more than 1.5).
SimulationSetup pulsed_bar() {
  SimulationSetup s;
  s.section = {1, PlaneMode::Stress, 1, 1e-4};
  s.materials = {{1e9, 1000, 0.0}, {7e9, 3000, 0.0}};
  using geometry::Box;
  s.points = geometry::fill_lattice(
      {{Box{{0, 0, 0}, {0.05, 0, 0}}, 1e-3, 0}, {Box{{0.05, 0, 0}, {0.1, 0, 0}}, 2e-3, 1}}, 1);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.1, 0, 0}};
  ic.velocity = Vec3{1.0, 0, 0};
  ic.gaussian_width = 0.005;
  ic.gaussian_center = {0.05, 0, 0};
  s.initial_conditions = {ic};
  return s;
}

TEST(Guard, DtAboveTheStableStepIsCaughtWithinAFewSteps) {
  auto s = pulsed_bar();
  const double stable = Simulation(s).critical_dt();
  s.fixed_dt = 1.5 * stable;
  Simulation sim(s);
  std::int64_t steps = 0;
  try {
    for (; steps < 1000; ++steps) sim.step();
    ADD_FAILURE() << "1000 steps at 1.5 x the stable step ran without the guard stopping them";
  } catch (const InstabilityError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("1.5 x the stable step"), std::string::npos) << what;
    EXPECT_NE(what.find("id "), std::string::npos) << what;
  }
  EXPECT_LT(steps, 300);
  // Just below the stable step the same run goes on.
  s.fixed_dt = 0.99 * stable;
  Simulation below(s);
  EXPECT_NO_THROW(below.run_steps(1000));
  EXPECT_NO_THROW(below.check_stable(below.energies()));
}

}  // namespace
}  // namespace dhpd
