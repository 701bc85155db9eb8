// The refiner's selection (docs/theory.md §13.2): grading keeps bond partners within one level, and
// `within` keeps the triggered split (buffer included) inside its regions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>

#include "engine/simulation.hpp"
#include "refine/refiner.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::Box;
using test::plate;

TEST(Refinement, GradingKeepsNeighboursWithinOneLevel) {
  refine::Settings set;
  set.max_level = 3;
  set.zones = {Box{{0.009, 0.009, 0}, {0.011, 0.011, 0}}};
  Simulation sim(plate(1e-3, 0.02, 0.02));
  const auto events = refine::Refiner(set).refine_zones(sim);
  ASSERT_EQ(events.size(), 3u);
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  EXPECT_EQ(*std::max_element(p.level.begin(), p.level.end()), 3);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      EXPECT_LE(std::abs(p.level[i] - p.level[static_cast<std::size_t>(b.other[k])]), 1);
  const double area = std::accumulate(p.volume.begin(), p.volume.end(), 0.0) / 1e-3;
  EXPECT_NEAR(area, 4e-4, 1e-16);
}

TEST(Refinement, TriggersSplitOnlyWithinTheGivenRegions) {
  // A plate strained uniformly to 0.6 s0: the stretch trigger (0.5 s0) marks every particle;
  // `within` keeps the split to the left half, buffer included.
  const auto s = test::strained_plate(0.02, 0.01, 0.6);
  refine::Settings set;
  set.trigger.stretch = 0.5;
  set.buffer = 2.0;
  for (const bool restricted : {false, true}) {
    if (restricted) set.within = {Box{{0, 0, 0}, {0.01, 0.01, 0}}};
    Simulation sim(s);
    const auto ev = refine::Refiner(set).check(sim);
    const auto& p = sim.particles();
    std::size_t outside = 0, refined = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      refined += p.level[i] > 0 ? 1 : 0;
      outside += p.level[i] > 0 && p.reference_position[0][i] > 0.01 ? 1 : 0;
    }
    std::printf("within %s: %zu parents, %zu refined particles right of x = 10 mm\n",
                restricted ? "left half" : "(none)", ev.parents, outside);
    EXPECT_EQ(ev.parents, restricted ? 100u : 200u);
    EXPECT_EQ(outside, restricted ? 0u : refined / 2);
  }
}
TEST(Refinement, ChecksComeAsOftenInTimeWithTimeLevels) {
  // check_every counts steps of the finest level: with two levels (dt0 = 2 × the finest step) a
  // check every 10 finest steps is one every 5 coarse steps; never less than every step.
  refine::Settings set;
  set.trigger.damage = 0.1;
  set.check_every = 10;
  const refine::Refiner refiner(set);
  std::vector<std::int64_t> one, two, deep;
  for (std::int64_t k = 1; k <= 20; ++k) {
    if (refiner.due(k)) one.push_back(k);
    if (refiner.due(k, 2)) two.push_back(k);
    if (refiner.due(k, 6)) deep.push_back(k);
  }
  EXPECT_EQ(one, (std::vector<std::int64_t>{10, 20}));
  EXPECT_EQ(two, (std::vector<std::int64_t>{5, 10, 15, 20}));
  EXPECT_EQ(deep.size(), 20u);
  refine::Settings none;  // no trigger: never due
  none.trigger = {};
  EXPECT_FALSE(refine::Refiner(none).due(10, 2));
}
}  // namespace
}  // namespace dhpd
