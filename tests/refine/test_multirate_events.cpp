// Multi-rate stepping through refinement events (docs/theory.md §19): the children take the fine
// level at the event, the run is the same with 1 and 2 threads, and a restart from a checkpoint
// continues it bit for bit (positions, velocities, bond states) with events on both sides.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <memory>
#include <optional>

#include "engine/checkpoint/checkpoint.hpp"
#include "tests/support/adaptive_run.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

SimulationSetup multirate_plate(std::optional<bool> multirate = true) {
  auto s = test::pulled_plate();
  s.multirate = multirate;
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
  whole.advance(60);  // two events so far (checks every 5 finest steps: 2 of dt0 with 2 levels)
  ASSERT_NE(whole.sim.time_levels(), nullptr) << "the children step at their own level";
  EXPECT_EQ(whole.sim.time_levels()->count(), 2);
  for (std::size_t i = 0; i < whole.sim.particles().size(); ++i)
    if (whole.sim.particles().level[i] > 0) {
      ASSERT_GE(whole.sim.time_levels()->level[i], 1);
    }
  whole.advance(190);  // by step 100 every particle is split: one level again
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

TEST(MultiRateEvents, ByDefaultASmallPatchTakesLevelsAndRestartsAreExact) {
  // time.multirate unset, a 60 × 24 mm plate refined only ahead of its notch tip: the small patch
  // pays for its levels, which the run takes; a restart from a checkpoint taken while levels are
  // used continues the run bit for bit (events on both sides of a checkpoint: the test above).
  const auto run = [] {
    auto s = multirate_plate(std::nullopt);
    s.points = geometry::fill_lattice({{geometry::Box{{0, 0, 0}, {0.06, 0.024, 0}}, 5e-4, 0}}, 2);
    s.cracks = {{{{0.0, 0.012, 0}, {0.012, 0.012, 0}}}};
    test::pull_apart(s, BoundaryCondition::Kind::Traction,
                     geometry::Box{{0, 0.0225, 0}, {0.06, 0.024, 0}},
                     geometry::Box{{0, 0, 0}, {0.06, 0.0015, 0}}, 25e6);
    auto r = std::make_unique<test::AdaptiveRun>(s);
    refine::Settings set;
    set.trigger.damage = 0.02;
    set.max_level = 1;
    set.check_every = 5;
    set.within = {geometry::Box{{0.009, 0.009, 0}, {0.03, 0.015, 0}}};
    r->refiner.emplace(set);
    return r;
  };
  const auto whole = run(), first = run(), second = run();
  std::int64_t levelled = 0;  // the first step with levels
  while (levelled == 0 && whole->sim.steps_done() < 300) {
    whole->advance(1);
    if (whole->sim.time_levels()) levelled = whole->sim.steps_done();
  }
  ASSERT_GT(levelled, 0) << "a small refined patch pays for its levels";
  whole->advance(250 - whole->sim.steps_done() + levelled);
  first->advance(levelled);
  ASSERT_NE(first->sim.time_levels(), nullptr);
  load_simulation(save_simulation(first->sim), second->sim, "test");
  second->advance(250);
  EXPECT_GE(first->events, 1) << "events before the checkpoint";
  expect_same_state(whole->sim, second->sim);
}

}  // namespace
}  // namespace dhpd
