// The guard's copy across refinement events (engine/checkpoint/guard_copy.hpp): taken before
// events and re-sorts, with before_edit announced by the refiner's event check as the run loop
// does, it restores the state of a run stopped when it was taken, bit for bit; an edit that was
// not announced is refused instead of restoring a wrong state.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>

#include "engine/checkpoint/checkpoint.hpp"
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

// Taken right after an event (its rows have room between them, no re-sort packed them) and
// restored after more events: the whole state comes back packed and the step part's bond states
// are packed to fit it (a static load step that refines several times, then fails, does this).
TEST(GuardCopy, ComesBackAfterEventsThatLeftRoomBetweenRows) {
  auto setup = test::pulled_plate();
  setup.resort_fraction = 0.0;  // never packed again by a re-sort
  AdaptiveRun run(setup);
  int k = 0;
  while (run.events == 0 && k++ < 400) run.advance(1);
  ASSERT_EQ(run.events, 1) << "an event within 400 steps";
  const auto& rows = run.sim.bonds().rows;
  ASSERT_GT(rows.arena, static_cast<std::int64_t>(run.sim.bonds().live))
      << "room between rows after the event";
  AdaptiveRun stopped(setup);
  stopped.advance(run.sim.steps_done());
  GuardCopy copy;
  copy.take(run.sim);
  run.refiner->set_event_check(
      [&copy](const Simulation& sim, std::size_t) { copy.before_edit(sim); });
  run.advance(120);
  ASSERT_GE(run.events, 3) << "events after the copy";
  copy.restore(run.sim);
  // The restored rows are packed: compare with the stopped run's state packed the same way.
  std::vector<std::byte> packed;
  save_simulation_into(stopped.sim, packed);
  load_simulation(packed, stopped.sim, "the stopped run");
  test::expect_identical(run.sim, stopped.sim);
  // The restored run goes on as the stopped one does.
  run.sim.run_steps(10);
  stopped.sim.run_steps(10);
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
