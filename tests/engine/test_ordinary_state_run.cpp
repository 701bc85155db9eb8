// Ordinary state-based DH-PD in the time stepper (docs/theory.md §20): its Lanczos step against
// the limit measured by bisection, energy conservation, restarts bit for bit, and the same
// numbers with 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstdio>

#include "engine/checkpoint/checkpoint.hpp"
#include "tests/support/checkpoint.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

/// `s` as an ordinary state-based run with Poisson's ratio nu (1D: none).
SimulationSetup state_based(SimulationSetup s, double nu, Influence w = Influence::Constant) {
  s.family = ModelFamily::OrdinaryState;
  s.influence = w;
  s.interface_correction = false;
  for (auto& m : s.materials) m.nu = s.section.dim == 1 ? std::nan("") : nu;
  return s;
}

struct Case {
  const char* name;
  SimulationSetup (*setup)();
};

const Case kCases[] = {
    {"bar 1D", [] { return state_based(test::pulsed_bar_1d(), 0.0); }},
    {"plate ν = 0 (two spacings)", [] { return state_based(test::ringing_plate(true), 0.0); }},
    {"plate ν = 0.3 plane strain",
     [] {
       auto s = state_based(test::ringing_plate(false), 0.3, Influence::InverseDistance);
       s.section.plane = PlaneMode::Strain;
       return s;
     }},
    {"block 3D ν = 0.3",  // strains of 1e-4: the linear regime
     [] { return state_based(test::pulsed_block_3d(1e-7), 0.3); }},
};

class StateStableStep : public ::testing::TestWithParam<Case> {};

// The run's step (Lanczos on the linearised state-based operator) against the limit of a fixed
// dt found by bisection: at or just above it, as for bond-based PD.
TEST_P(StateStableStep, TheEstimateIsWithinOnePercentOfTheMeasuredLimit) {
  const auto s = GetParam().setup();
  const double estimate = Simulation(s).critical_dt();
  const double limit = test::measured_limit(s, 0.8 * estimate, 1.2 * estimate);
  std::printf("%s: measured limit / Lanczos estimate %.4f\n", GetParam().name, limit / estimate);
  EXPECT_GE(limit / estimate, 0.99);
  EXPECT_LE(limit / estimate, 1.005);
}

// Velocity Verlet with a conservative force: kinetic + strain energy less the Verlet correction
// stays where it started (safety 0.9, 3,000 steps), with horizons that differ by 2×.
TEST_P(StateStableStep, ShadowEnergyIsConserved) {
  auto s = GetParam().setup();
  s.safety = 0.9;
  Simulation sim(s);
  const auto e0 = sim.energies();
  const double start = e0.kinetic + e0.strain - e0.verlet_correction;
  double worst = 0.0;
  for (int k = 0; k < 30; ++k) {
    sim.run_steps(100);
    const auto e = sim.energies();
    worst = std::max(worst, std::abs(e.kinetic + e.strain - e.verlet_correction - start) / start);
  }
  std::printf("%s: shadow energy drift ≤ %.2e over 3000 steps\n", GetParam().name, worst);
  EXPECT_GT(start, 0.0);
  EXPECT_LT(worst, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Bodies, StateStableStep, ::testing::ValuesIn(kCases));

TEST(StateRun, RestartIsBitExactAndThreadsAgree) {
  const auto s = state_based(test::ringing_plate(true), 0.25);
  Simulation whole(s);
  whole.run_steps(200);
  test::expect_restart_and_one_thread_exact(s, whole, 120, 80);
}

}  // namespace
}  // namespace dhpd
