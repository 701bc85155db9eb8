// The guard's copy across refinement events (engine/checkpoint/guard_copy.hpp): taken before
// events and re-sorts, with before_edit announced by the refiner's event check as the run loop
// does, it restores the state of a run stopped when it was taken, bit for bit; an edit that was
// not announced is refused instead of restoring a wrong state.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>

#include "engine/checkpoint/guard_copy.hpp"
#include "refine/refiner.hpp"
#include "tests/support/adaptive_run.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

using test::AdaptiveRun;

SimulationSetup resorting_plate() {
  auto setup = test::pulled_plate();
  setup.resort_fraction = 0.02;  // re-sorts after most events
  return setup;
}

TEST(GuardCopy, ComesBackBitForBitAcrossEventsAndResorts) {
  const auto setup = resorting_plate();
  AdaptiveRun run(setup), stopped(setup);
  run.advance(100);
  stopped.advance(100);
  GuardCopy copy;
  copy.take(run.sim);
  run.refiner->set_event_check(
      [&copy](const Simulation& sim, std::size_t) { copy.before_edit(sim); });
  const int events_before = run.events, resorts_before = run.resorts;
  run.advance(80);
  ASSERT_GE(run.events - events_before, 2) << "events after the copy";
  ASSERT_GE(run.resorts - resorts_before, 1) << "a re-sort after the copy";
  EXPECT_TRUE(copy.holds_whole_state());
  copy.restore(run.sim);
  test::expect_identical(run.sim, stopped.sim);
}

TEST(GuardCopy, AnEditWithoutBeforeEditIsRefused) {
  AdaptiveRun run(resorting_plate());
  run.advance(100);
  GuardCopy copy;
  copy.take(run.sim);
  const int events_before = run.events;
  run.advance(80);
  ASSERT_GT(run.events, events_before);
  EXPECT_THROW(copy.restore(run.sim), std::logic_error);
}

}  // namespace
}  // namespace dhpd
