// Multi-rate stepping through refinement events (docs/theory.md §19): the children take the fine
// level at the event, the run is the same with 1 and 2 threads, and a restart from a checkpoint
// continues it bit for bit (positions, velocities, bond states) with events on both sides.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>

#include "engine/checkpoint/checkpoint.hpp"
#include "tests/support/adaptive_run.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

SimulationSetup multirate_plate() {
  auto s = test::pulled_plate();
  s.multirate = true;
  return s;
}

void expect_same_state(const Simulation& a, const Simulation& b) {
  ASSERT_EQ(a.particles().size(), b.particles().size());
  EXPECT_EQ(a.steps_done(), b.steps_done());
  EXPECT_EQ(a.time(), b.time());
  EXPECT_EQ(a.dt(), b.dt());
  EXPECT_EQ(a.broken_bonds(), b.broken_bonds());
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_EQ(a.particles().position[axis], b.particles().position[axis]) << axis;
    EXPECT_EQ(a.particles().velocity[axis], b.particles().velocity[axis]) << axis;
  }
  // Row by row (the restored arena may be laid out more tightly).
  const auto &x = a.bonds(), &y = b.bonds();
  std::int64_t differ = 0;
  for (std::size_t i = 0; i < a.particles().size(); ++i) {
    if (x.end(i) - x.begin(i) != y.end(i) - y.begin(i)) {
      ++differ;
      continue;
    }
    for (auto k = x.begin(i); k < x.end(i); ++k)
      differ += x.flags[k] != y.flags[k - x.begin(i) + y.begin(i)] ? 1 : 0;
  }
  EXPECT_EQ(differ, 0);
}

TEST(MultiRateEvents, ChildrenTakeTheFineLevelAndRestartsAreExact) {
  test::AdaptiveRun whole(multirate_plate()), first(multirate_plate());
  whole.advance(110);
  ASSERT_NE(whole.sim.time_levels(), nullptr) << "the children step at their own level";
  EXPECT_EQ(whole.sim.time_levels()->count(), 2);
  for (std::size_t i = 0; i < whole.sim.particles().size(); ++i)
    if (whole.sim.particles().level[i] > 0) {
      ASSERT_GE(whole.sim.time_levels()->level[i], 1);
    }
  whole.advance(140);  // by step 135 every particle is split: one level again
  EXPECT_EQ(whole.sim.time_levels(), nullptr);
  first.advance(60);
  test::AdaptiveRun second(multirate_plate());
  load_simulation(save_simulation(first.sim), second.sim, "test");
  second.advance(190);
  EXPECT_GE(first.events, 2) << "events before the checkpoint";
  EXPECT_GE(second.events, 2) << "events after it";
  expect_same_state(whole.sim, second.sim);
}

TEST(MultiRateEvents, OneAndTwoThreadsGiveTheSameRun) {
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  test::AdaptiveRun one(multirate_plate());
  one.advance(200);
  omp_set_num_threads(2);
  test::AdaptiveRun two(multirate_plate());
  two.advance(200);
  omp_set_num_threads(threads);
  EXPECT_GT(one.events, 0);
  expect_same_state(one.sim, two.sim);
}

}  // namespace
}  // namespace dhpd
