// Multi-rate stepping through refinement events (docs/theory.md §19): the children take the fine
// level at the event, the run is the same with 1 and 2 threads, and a restart from a checkpoint
// continues it bit for bit (positions, velocities, bond states) with events on both sides; the
// regrouping by level after an event leaves the state a renumbering of the whole body gives.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

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

/// A 60 × 24 mm plate with a notch, pulled apart.
SimulationSetup notched_plate(std::optional<bool> multirate) {
  auto s = multirate_plate(multirate);
  s.points = geometry::fill_lattice({{geometry::Box{{0, 0, 0}, {0.06, 0.024, 0}}, 5e-4, 0}}, 2);
  s.cracks = {{{{0.0, 0.012, 0}, {0.012, 0.012, 0}}}};
  test::pull_apart(s, BoundaryCondition::Kind::Traction,
                   geometry::Box{{0, 0.0225, 0}, {0.06, 0.024, 0}},
                   geometry::Box{{0, 0, 0}, {0.06, 0.0015, 0}}, 25e6);
  return s;
}

/// The notched plate refined only ahead of its notch tip (a small patch).
std::unique_ptr<test::AdaptiveRun> notch_patch_run(std::optional<bool> multirate) {
  auto r = std::make_unique<test::AdaptiveRun>(notched_plate(multirate));
  refine::Settings set;
  set.trigger.damage = 0.02;
  set.max_level = 1;
  set.check_every = 5;
  set.within = {geometry::Box{{0.009, 0.009, 0}, {0.03, 0.015, 0}}};
  r->refiner.emplace(set);
  return r;
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

TEST(MultiRateEvents, RegroupingByLevelGivesTheStateOfAWholeRenumbering) {
  // An event's re-levelling moves only the particles outside their level's block (docs/theory.md
  // §19.3). The same state renumbered as a whole (compact: Morton order within levels, rows
  // packed) must hold the same particles, levels, bonds and forces, particle by particle.
  const auto patch = notch_patch_run(true);
  auto& run = *patch;
  bool regrouped = false;
  while (!regrouped && run.sim.steps_done() < 400) {
    const auto layout = run.sim.layout_version();
    run.advance(1);
    regrouped = run.sim.layout_version() != layout && run.sim.appended_since_compaction() > 0 &&
                run.sim.time_levels() != nullptr;
  }
  ASSERT_TRUE(regrouped) << "no event re-levelled in place by step " << run.sim.steps_done() << " ("
                         << run.events << " events)";
  Simulation whole(notched_plate(true));
  load_simulation(save_simulation(run.sim), whole, "test");
  whole.compact();
  const auto &a = run.sim.particles(), &b = whole.particles();
  ASSERT_EQ(a.size(), b.size());
  std::map<std::int32_t, std::size_t> slot_of_id;
  for (std::size_t i = 0; i < b.size(); ++i) slot_of_id[b.id[i]] = i;
  ASSERT_NE(whole.time_levels(), nullptr);
  std::size_t moved_slot = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto j = slot_of_id.at(a.id[i]);
    moved_slot += i != j ? 1 : 0;
    EXPECT_EQ(run.sim.time_levels()->level[i], whole.time_levels()->level[j]) << a.id[i];
    EXPECT_NEAR(a.damage[i], b.damage[j], 1e-14) << a.id[i];  // summed in another order
    for (int axis = 0; axis < 2; ++axis) {
      EXPECT_EQ(a.position[axis][i], b.position[axis][j]);
      EXPECT_EQ(a.velocity[axis][i], b.velocity[axis][j]);
      EXPECT_NEAR(a.force_density[axis][i], b.force_density[axis][j],
                  1e-9 * (1.0 + std::abs(b.force_density[axis][j])))
          << a.id[i];
    }
    // The same bonds in the same states, by the ids of their ends.
    const auto &x = run.sim.bonds(), &y = whole.bonds();
    ASSERT_EQ(x.end(i) - x.begin(i), y.end(j) - y.begin(j)) << a.id[i];
    std::map<std::int32_t, std::uint8_t> flags;
    for (auto k = y.begin(j); k < y.end(j); ++k)
      flags[b.id[static_cast<std::size_t>(y.other[k])]] = y.flags[k];
    for (auto k = x.begin(i); k < x.end(i); ++k)
      EXPECT_EQ(x.flags[k], flags.at(a.id[static_cast<std::size_t>(x.other[k])])) << a.id[i];
  }
  EXPECT_GT(moved_slot, 0u) << "the whole renumbering puts particles elsewhere";
}

TEST(MultiRateEvents, KeptLevelForcesEqualAFreshEvaluation) {
  // After an event the rows it left alone keep their level forces (docs/theory.md §19.3); a copy
  // of the state loaded from a checkpoint evaluates every level's forces anew. Bit for bit, for
  // events that find levels in use: the pulled plate's and the notch patch's.
  struct Case {
    std::unique_ptr<test::AdaptiveRun> run;
    SimulationSetup setup;
  };
  std::vector<Case> cases;
  cases.push_back({std::make_unique<test::AdaptiveRun>(multirate_plate()), multirate_plate()});
  cases.push_back({notch_patch_run(true), notched_plate(true)});
  int compared = 0;
  for (auto& c : cases) {
    auto& run = *c.run;
    while (run.sim.steps_done() < 300) {
      const auto generation = run.sim.generation();
      const bool levelled = run.sim.time_levels() != nullptr;
      run.advance(1);
      if (!levelled || run.sim.generation() == generation || !run.sim.time_levels()) continue;
      Simulation fresh(c.setup);
      load_simulation(save_simulation(run.sim), fresh, "test");
      const auto &kept = *run.sim.time_levels(), &anew = *fresh.time_levels();
      ASSERT_EQ(kept.count(), anew.count());
      for (int l = 0; l < kept.count(); ++l)
        for (int a = 0; a < 2; ++a)
          EXPECT_EQ(kept.plans[static_cast<std::size_t>(l)].force[a],
                    anew.plans[static_cast<std::size_t>(l)].force[a])
              << "level " << l << " axis " << a << " at step " << run.sim.steps_done();
      for (int a = 0; a < 2; ++a)
        EXPECT_EQ(run.sim.particles().force_density[a], fresh.particles().force_density[a]);
      ++compared;
    }
  }
  EXPECT_GE(compared, 3) << "events that found time levels in use";
}

TEST(MultiRateEvents, ByDefaultASmallPatchTakesLevelsAndRestartsAreExact) {
  // time.multirate unset, a 60 × 24 mm plate refined only ahead of its notch tip: the small patch
  // pays for its levels, which the run takes; a restart from a checkpoint taken while levels are
  // used continues the run bit for bit (events on both sides of a checkpoint: the test above).
  const auto run = [] { return notch_patch_run(std::nullopt); };
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
