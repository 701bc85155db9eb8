// The incremental search grid of refinement events (refine/spatial_grid.*) against a brute-force
// scan of what it holds: points of mixed spacings (one cell grid per spacing class), queries of any
// radius anywhere, the predicate |X_j - x|² < r² (the k-d tree's), ascending order and the skipped
// index; after removals, re-insertion of an index at a new position and with a new spacing, and
// with points whose cell keys alias (21 bits per axis) and queries wider than the key range; and
// after following a renumbering of a few slots (a regrouping by time level).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "geometry/vec.hpp"
#include "refine/spatial_grid.hpp"

namespace dhpd {
namespace {

using geometry::Vec3;
using refine::SpatialGrid;

/// What the grid should hold: index -> reference position.
struct Model {
  int dim;
  std::map<std::int32_t, Vec3> points;

  std::vector<std::int32_t> within(const Vec3& x, double r, std::int32_t skip = -1) const {
    std::vector<std::int32_t> out;  // std::map iterates in ascending index order
    for (const auto& [j, y] : points) {
      double d2 = 0.0;
      for (int a = 0; a < dim; ++a) {
        const double d = x[a] - y[a];
        d2 += d * d;
      }
      if (d2 < r * r && j != skip) out.push_back(j);
    }
    return out;
  }
};

/// Both hold the same points.
struct Pair {
  Pair(int dim, double base, double ratio) : grid(dim, base, ratio), model{dim, {}} {}
  void insert(std::int32_t i, const Vec3& x, double spacing) {
    grid.insert(i, x, spacing);
    model.points[i] = x;
  }
  void remove(std::int32_t i) {
    grid.remove(i);
    model.points.erase(i);
  }
  SpatialGrid grid;
  Model model;
};

Vec3 random_point(std::mt19937_64& rng, int dim, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Vec3 x{0, 0, 0};
  for (int a = 0; a < dim; ++a) x[a] = u(rng);
  return x;
}

/// Queries around held points (with their own index skipped or not) and at random places, with
/// radii from below the finest spacing to several coarse cells; returns the neighbours found.
std::size_t expect_same_answers(const Pair& g, std::mt19937_64& rng, double base, int queries) {
  std::uniform_real_distribution<double> radius(0.0, 4.0 * base);
  std::vector<std::int32_t> found;
  std::size_t total = 0;
  std::vector<std::int32_t> held;
  for (const auto& [i, x] : g.model.points) held.push_back(i);
  for (int q = 0; q < queries; ++q) {
    const double r = q % 7 == 0 ? base : radius(rng);  // base: a cell edge of the coarse class
    Vec3 x{0, 0, 0};
    std::int32_t skip = -1;
    if (q % 2 == 0 && !held.empty()) {
      skip = held[static_cast<std::size_t>(rng() % held.size())];
      x = g.model.points.at(skip);
      if (q % 4 == 0) skip = -1;  // then the query point itself is found (distance 0)
    } else {
      x = random_point(rng, g.model.dim, -0.1, 1.1);
    }
    found.assign(2, -5);  // within() clears what was there
    g.grid.within(x, r, found, skip);
    const auto expected = g.model.within(x, r, skip);
    EXPECT_TRUE(std::is_sorted(found.begin(), found.end()));
    EXPECT_EQ(found, expected) << g.model.dim << "D query " << q << " r=" << r << " skip " << skip;
    if (found != expected) return total;
    total += found.size();
  }
  return total;
}

TEST(SpatialGrid, MixedSpacingsMatchBruteForceIn1d2d3d) {
  for (const int dim : {1, 2, 3}) {
    std::mt19937_64 rng(100 + dim);
    const double base = dim == 1 ? 4e-3 : (dim == 2 ? 0.04 : 0.1);
    Pair g(dim, base, 3.015);
    // Spacing classes base, base/2, base/4 and one that is no power of two (rounded to a class).
    const double spacings[4] = {base, base / 2, base / 4, 0.3 * base};
    const int n = dim == 3 ? 1500 : 800;
    for (std::int32_t i = 0; i < n; ++i)
      g.insert(i, random_point(rng, dim, 0.0, 1.0), spacings[static_cast<std::size_t>(i) % 4]);
    for (std::int32_t i = 0; i < n; ++i) EXPECT_TRUE(g.grid.contains(i));
    EXPECT_FALSE(g.grid.contains(n));
    EXPECT_GT(expect_same_answers(g, rng, base, 600), 600u) << dim;
  }
}

TEST(SpatialGrid, RemovalsAndReinsertionAtANewPositionMatchBruteForce) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(7 + dim);
    const double base = dim == 2 ? 0.05 : 0.12;
    Pair g(dim, base, 3.015);
    const int n = 900;
    for (std::int32_t i = 0; i < n; ++i)
      g.insert(i, random_point(rng, dim, 0.0, 1.0), i % 3 == 0 ? base : base / 2);
    // An event's pattern: remove parents, insert children at new indices and one child in each
    // parent's slot; also move some points without removing them first (insert replaces).
    for (int round = 0; round < 4; ++round) {
      for (int k = 0; k < 120; ++k) {
        const auto i = static_cast<std::int32_t>(rng() % n);
        g.remove(i);
        EXPECT_FALSE(g.grid.contains(i));
        g.remove(i);  // removing an absent index is a no-op
      }
      for (int k = 0; k < 60; ++k) {
        const auto i = static_cast<std::int32_t>(rng() % n);
        g.insert(i, random_point(rng, dim, 0.0, 1.0), base / 4);  // re-inserted or moved
        EXPECT_TRUE(g.grid.contains(i));
      }
      for (int k = 0; k < 40; ++k) {
        const auto i = static_cast<std::int32_t>(n + 40 * round + k);
        g.insert(i, random_point(rng, dim, 0.0, 1.0), base / 4);
      }
      EXPECT_GT(expect_same_answers(g, rng, base, 300), 100u) << dim << " round " << round;
    }
    // A moved point is found at its new place only.
    const Vec3 far{5.0, 5.0, dim == 3 ? 5.0 : 0.0};
    const auto old_place = g.model.points.at(n + 1);
    g.insert(n + 1, far, base);
    std::vector<std::int32_t> found;
    g.grid.within(old_place, 1e-9, found);
    EXPECT_EQ(std::count(found.begin(), found.end(), n + 1), 0);
    g.grid.within(far, 1e-9, found);
    EXPECT_EQ(found, (std::vector<std::int32_t>{n + 1}));
    EXPECT_EQ(found, g.model.within(far, 1e-9));
  }
}

TEST(SpatialGrid, FollowingMovedSlotsAnswersAsTheRenumberedPoints) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(31 + dim);
    const double base = dim == 2 ? 0.05 : 0.12;
    Pair g(dim, base, 3.015);
    const int n = 900;
    for (std::int32_t i = 0; i < n; ++i)
      g.insert(i, random_point(rng, dim, 0.0, 1.0), i % 3 == 0 ? base : base / 2);
    g.remove(5);  // an absent slot may take part in a move
    for (int round = 0; round < 3; ++round) {
      // A permutation of a few slots, cycles included: slot moved[t] gets source[t]'s particle.
      std::vector<std::int32_t> moved;
      for (int k = 0; k < 40; ++k) moved.push_back(static_cast<std::int32_t>(rng() % n));
      moved.push_back(5);
      std::sort(moved.begin(), moved.end());
      moved.erase(std::unique(moved.begin(), moved.end()), moved.end());
      auto source = moved;
      std::shuffle(source.begin(), source.end(), rng);
      g.grid.move_slots(moved, source);
      std::map<std::int32_t, Vec3> renumbered;
      for (const auto& [i, x] : g.model.points) renumbered[i] = x;
      for (std::size_t t = 0; t < moved.size(); ++t) {
        renumbered.erase(moved[t]);
        const auto from = g.model.points.find(source[t]);
        if (from != g.model.points.end()) renumbered[moved[t]] = from->second;
      }
      g.model.points = renumbered;
      for (const auto i : moved) EXPECT_EQ(g.grid.contains(i), g.model.points.count(i) == 1);
      EXPECT_GT(expect_same_answers(g, rng, base, 400), 100u) << dim << " round " << round;
    }
  }
}

TEST(SpatialGrid, TheComparisonIsStrictAndExcludesTheSkippedIndexOnly) {
  // On a lattice of spacing 1/8 (exact binary coordinates) the nearest neighbours lie exactly at
  // r = 1/8: left out; just beyond it they are in, in ascending index order.
  const double h = 0.125;
  Pair g(2, h, 3.0);
  std::int32_t i = 0;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) g.insert(i++, Vec3{x * h, y * h, 0}, h);
  std::vector<std::int32_t> found;
  g.grid.within(Vec3{2 * h, 2 * h, 0}, h, found, 12);
  EXPECT_TRUE(found.empty());
  g.grid.within(Vec3{2 * h, 2 * h, 0}, std::nextafter(h, 1.0), found, 12);
  EXPECT_EQ(found, (std::vector<std::int32_t>{7, 11, 13, 17}));
  g.grid.within(Vec3{2 * h, 2 * h, 0}, std::nextafter(h, 1.0), found);  // no skip: 12 itself too
  EXPECT_EQ(found, (std::vector<std::int32_t>{7, 11, 12, 13, 17}));
  g.grid.within(Vec3{2 * h, 2 * h, 0}, std::nextafter(h, 1.0), found, 7);
  EXPECT_EQ(found, (std::vector<std::int32_t>{11, 12, 13, 17}));
  // Negative coordinates (cells below zero) and a query between cells.
  g.insert(100, Vec3{-0.3, -0.2, 0}, h);
  g.insert(101, Vec3{-0.31, -0.2, 0}, h / 2);
  g.grid.within(Vec3{-0.305, -0.2, 0}, 0.006, found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{100, 101}));
}

TEST(SpatialGrid, PointsWhoseCellKeysAliasAreNotReported) {
  // 21 bits per axis: a point 2^21 cells away along x shares the query cell's key. It is a
  // candidate, but the distance check drops it; a twin at the query's own place is found.
  const double base = 1.0, ratio = 1.0;  // the coarse class's cell edge is 1
  Pair g(2, base, ratio);
  const double wrap = std::ldexp(1.0, 21);
  g.insert(0, Vec3{0.5, 0.5, 0}, base);
  g.insert(1, Vec3{0.5 + wrap, 0.5, 0}, base);
  g.insert(2, Vec3{0.5, 0.5 - wrap, 0}, base);
  std::vector<std::int32_t> found;
  g.grid.within(Vec3{0.5, 0.5, 0}, 0.25, found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{0}));
  g.grid.within(Vec3{0.5 + wrap, 0.5, 0}, 0.25, found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{1}));
  EXPECT_EQ(found, g.model.within(Vec3{0.5 + wrap, 0.5, 0}, 0.25));
  // A query wider than 2^21 cells visits a key more than once: each point is still reported once.
  Pair line(1, base, ratio);
  line.insert(0, Vec3{0.5, 0, 0}, base);
  line.insert(1, Vec3{3.5, 0, 0}, base);
  line.grid.within(Vec3{0.5, 0, 0}, wrap, found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{0, 1}));
}

}  // namespace
}  // namespace dhpd
