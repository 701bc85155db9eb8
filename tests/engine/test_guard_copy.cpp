// The guard's copy (engine/checkpoint/guard_copy.hpp): taken after N steps, restored after more
// steps with fracture, it gives back the state of a run stopped at N bit for bit, and both go on
// identically; it holds a fraction of the whole state. (Across refinement events:
// tests/refine/test_guard_copy_events.cpp.)
#include <gtest/gtest.h>

#include <iostream>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/checkpoint/guard_copy.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

void expect_restores_exactly(const SimulationSetup& setup, std::int64_t taken, std::int64_t more) {
  Simulation sim(setup), stopped(setup);
  sim.run_steps(taken);
  stopped.run_steps(taken);
  GuardCopy copy;
  EXPECT_TRUE(copy.empty());
  copy.take(sim);
  const auto broken_then = sim.broken_bonds();
  sim.run_steps(more);
  ASSERT_GT(sim.broken_bonds(), broken_then) << "bonds must break after the copy";
  copy.restore(sim);
  EXPECT_FALSE(copy.holds_whole_state());
  test::expect_identical(sim, stopped);
  sim.run_steps(more);
  stopped.run_steps(more);
  test::expect_identical(sim, stopped);
}

TEST(GuardCopy, FracturingPlateComesBackBitForBit) {
  expect_restores_exactly(test::pulled_plate(), 60, 60);
}

TEST(GuardCopy, BlockWithPrescribedVelocitiesComesBackBitForBit) {
  expect_restores_exactly(test::pulled_block_3d(), 40, 40);
}

TEST(GuardCopy, HoldsAFractionOfTheWholeState) {
  Simulation sim(test::pulled_plate());
  sim.run_steps(10);
  GuardCopy copy;
  copy.take(sim);
  const double whole = static_cast<double>(save_simulation(sim).size());
  std::cerr << "step part " << copy.bytes() << " B, whole state " << whole << " B\n";
  // What a step changes and nothing more: the particles' state fields (displacement, velocity,
  // force density, position: 4 vectors; damage), one flag byte per row entry, a few hundred bytes
  // of clocks and names; not the geometry, the rows' lengths and stiffness, loads or constants.
  const auto& p = sim.particles();
  const double state = static_cast<double>(p.size()) * (4 * 3 + 1) * sizeof(double) +
                       static_cast<double>(sim.bonds().flags.size());
  EXPECT_LE(static_cast<double>(copy.bytes()), state + 1024.0);
  EXPECT_GE(static_cast<double>(copy.bytes()), state);
  EXPECT_LT(static_cast<double>(copy.bytes()), whole);
  copy.before_edit(sim);  // an edit announced: the whole state joins the step part
  EXPECT_TRUE(copy.holds_whole_state());
  EXPECT_GT(static_cast<double>(copy.bytes()), whole);
  copy.take(sim);  // a new copy releases it
  EXPECT_FALSE(copy.holds_whole_state());
}

TEST(GuardCopy, StepStateOfAnotherDiscretisationIsRefused) {
  Simulation plate(test::pulled_plate()), block(test::pulled_block_3d());
  std::vector<std::byte> bytes;
  save_step_state_into(plate, bytes);
  EXPECT_THROW(load_step_state(bytes, block), InputError);
}

}  // namespace
}  // namespace dhpd
