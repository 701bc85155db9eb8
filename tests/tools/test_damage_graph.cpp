// The damage graph kept between crack measurements (docs/theory.md §15) equals the graph built
// anew at every measurement, link for link and bit for bit: while damage grows, after the state
// went back (a member's damage fell), after a refinement (a new revision), in 1D, 2D and 3D with
// spacings over a factor 4; and a tracker fed revisions measures the same rows as one without.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "tests/support/engine.hpp"
#include "tools/measure/crack_measure.hpp"
#include "tools/measure/damage_graph.hpp"

namespace dhpd::measure {
namespace {

void expect_same_graph(const DamageGraph& grown, const DamageGraph& fresh, const char* when) {
  EXPECT_EQ(grown.particle, fresh.particle) << when;
  EXPECT_EQ(grown.offset, fresh.offset) << when;
  EXPECT_EQ(grown.neighbor, fresh.neighbor) << when;
  ASSERT_EQ(grown.length.size(), fresh.length.size()) << when;
  EXPECT_EQ(0, std::memcmp(grown.length.data(), fresh.length.data(), 8 * grown.length.size()))
      << when;
}

/// Raises the damage of a random tenth of the particles by up to 0.3 (never lowers it).
void grow_damage(ParticleStore& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (unit(rng) < 0.1) p.damage[i] = std::min(1.0, p.damage[i] + 0.3 * unit(rng));
}

class GrowingGraph : public ::testing::TestWithParam<int> {};

TEST_P(GrowingGraph, EqualsAGraphBuiltAnewAtEveryMeasurement) {
  const int dim = GetParam();
  const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.02 : 0.06);
  auto p = test::random_cloud(dim, dim == 3 ? 3000 : 1500, h, 4.0, 3.015, 17);
  std::mt19937_64 rng(5);
  GrowingDamageGraph grown(0.35);
  std::size_t most_links = 0;
  for (int m = 0; m < 12; ++m) {
    grow_damage(p, rng);
    const auto& g = grown.update(p, {0, 0});
    expect_same_graph(g, damage_graph(p, 0.35), "while damage grows");
    most_links = std::max(most_links, g.neighbor.size());
  }
  EXPECT_GT(most_links, 2 * p.size() / 10);  // the test links many nodes, not a few
  // The state went back (a guard restore): a member lost its damage.
  const auto member = grown.update(p, {0, 0}).particle.at(7);
  p.damage[member] = 0.0;
  expect_same_graph(grown.update(p, {0, 0}), damage_graph(p, 0.35), "after damage fell");
  // A refinement edited the store: new revision, other particles.
  auto refined = test::random_cloud(dim, p.size() + 200, 0.5 * h, 4.0, 3.015, 23);
  for (int m = 0; m < 3; ++m) grow_damage(refined, rng);
  expect_same_graph(grown.update(refined, {1, 0}), damage_graph(refined, 0.35), "new revision");
  // Same size, renumbered (a compaction): a new layout starts again too.
  auto renumbered = test::random_cloud(dim, refined.size(), 0.5 * h, 4.0, 3.015, 29);
  renumbered.damage = refined.damage;
  expect_same_graph(grown.update(renumbered, {1, 1}), damage_graph(renumbered, 0.35), "new layout");
}

INSTANTIATE_TEST_SUITE_P(Dimensions, GrowingGraph, ::testing::Values(1, 2, 3));

TEST(GrowingGraph, ItsVersionChangesExactlyWhenTheGraphDoes) {
  auto p = test::random_cloud(2, 1500, 0.02, 4.0, 3.015, 41);
  std::mt19937_64 rng(9);
  GrowingDamageGraph grown(0.35);
  grow_damage(p, rng);
  grown.update(p, {0, 0});
  const auto first = grown.version();
  grown.update(p, {0, 0});
  EXPECT_EQ(grown.version(), first) << "nothing joined";
  grow_damage(p, rng);
  const auto size = grown.update(p, {0, 0}).particle.size();
  EXPECT_NE(grown.version(), first) << "particles joined";
  ASSERT_GT(size, 0u);
  const auto second = grown.version();
  grown.update(p, {1, 0});
  EXPECT_NE(grown.version(), second) << "a new revision starts the graph again";
}

TEST(GrowingGraph, ATrackerWithRevisionsMeasuresTheSameRows) {
  auto p = test::random_cloud(2, 2000, 0.01, 2.0, 3.015, 31);
  Settings s;
  s.smoothing = 2;
  s.tips = {{"a", {0.5, 0.5, 0}, {1, 0, 0}, std::nullopt, std::nullopt},
            {"b", {0.2, 0.2, 0}, {0, 1, 0}, std::nullopt, std::nullopt}};
  CrackTracker grown(s), fresh(s);
  std::mt19937_64 rng(3);
  double longest = 0.0;
  // Every other measurement sees the damage of the one before (the grown tracker then reuses
  // its crack paths and branches); at 13 the state goes back (a member's damage falls).
  for (int m = 0; m < 20; ++m) {
    if (m % 2 == 0) grow_damage(p, rng);
    if (m == 13)
      *std::find_if(p.damage.begin(), p.damage.end(),
                    [&](double d) { return d >= s.damage_threshold; }) = 0.0;
    const auto a = grown.measure(p, m, 1e-6 * m, Revision{0, 0});
    const auto b = fresh.measure(p, m, 1e-6 * m);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].x, b[k].x);
      EXPECT_EQ(a[k].path_length, b[k].path_length);
      EXPECT_EQ(a[k].branches, b[k].branches);
      EXPECT_EQ(a[k].speed, b[k].speed);
      longest = std::max(longest, a[k].path_length);
    }
  }
  EXPECT_GT(longest, 0.05);  // a crack of many spacings was followed
}

}  // namespace
}  // namespace dhpd::measure
