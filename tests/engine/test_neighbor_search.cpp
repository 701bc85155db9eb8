// The k-d tree (engine/discretization/neighbor_search.*) against a brute-force scan: for random
// 1D, 2D and 3D point sets, lattices (where many distances equal the radius exactly) and points
// that coincide, `within(i, r)` returns exactly the j != i with |X_j - X_i|² < r², sorted
// ascending. The comparison is strict: nanoflann 1.4.3 (RadiusResultSet::addPoint) keeps a point
// only when its squared distance is below r², so a point exactly at the radius is left out, the
// predicate refine/spatial_grid.hpp copies (the bond builder searches 1e-9 beyond the horizon).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "engine/discretization/neighbor_search.hpp"
#include "engine/discretization/particles.hpp"

namespace dhpd {
namespace {

/// Squared distance over the first `dim` axes, summed in axis order as the k-d tree does.
double distance2(const VectorArray& x, int dim, std::size_t i, std::size_t j) {
  double d2 = 0.0;
  for (int a = 0; a < dim; ++a) {
    const double d = x[a][i] - x[a][j];
    d2 += d * d;
  }
  return d2;
}

std::vector<std::int32_t> brute_force(const VectorArray& x, int dim, std::size_t i, double r) {
  std::vector<std::int32_t> out;
  for (std::size_t j = 0; j < x[0].size(); ++j)
    if (j != i && distance2(x, dim, i, j) < r * r) out.push_back(static_cast<std::int32_t>(j));
  return out;
}

VectorArray random_points(int dim, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  VectorArray x;
  for (auto& axis : x) axis.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < dim; ++a) x[a][i] = unit(rng);
  return x;
}

/// A lattice of spacing h (a power of two, so every coordinate and squared distance is exact).
VectorArray lattice(int dim, int cells, double h) {
  VectorArray x;
  const int ny = dim > 1 ? cells : 1, nz = dim > 2 ? cells : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < cells; ++i) {
        x[0].push_back(i * h);
        x[1].push_back(j * h);
        x[2].push_back(k * h);
      }
  return x;
}

/// Every query of `x` at every radius of `radii` equals brute force; returns how many neighbours
/// were found in all (so a test can tell it looked at non-trivial sets).
std::size_t expect_matches_brute_force(const VectorArray& x, int dim,
                                       const std::vector<double>& radii) {
  const NeighborSearch search(x, dim);
  std::vector<std::int32_t> found;
  std::size_t total = 0;
  for (const double r : radii)
    for (std::size_t i = 0; i < x[0].size(); ++i) {
      found.assign(3, -7);  // within() clears what was there
      search.within(i, r, found);
      const auto expected = brute_force(x, dim, i, r);
      EXPECT_TRUE(std::is_sorted(found.begin(), found.end())) << dim << "D i=" << i;
      EXPECT_EQ(std::count(found.begin(), found.end(), static_cast<std::int32_t>(i)), 0);
      EXPECT_EQ(found, expected) << dim << "D i=" << i << " r=" << r;
      if (found != expected) return total;  // one report per set is enough
      total += found.size();
    }
  return total;
}

TEST(NeighborSearch, RandomPointsMatchBruteForceIn1d2d3d) {
  for (const int dim : {1, 2, 3}) {
    const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 700 : 900);
    const auto x = random_points(dim, n, 17 + dim);
    // From a few neighbours to a good part of the set.
    const double h = dim == 1 ? 1.0 / 300 : (dim == 2 ? 0.04 : 0.1);
    const auto found = expect_matches_brute_force(x, dim, {0.0, 0.7 * h, 3.015 * h, 8.3 * h});
    EXPECT_GT(found, 10 * n) << dim;
  }
}

TEST(NeighborSearch, AroundAPointThatIsNotInTheSetMatchesBruteForce) {
  // around(x): every point within r of x, the query not being one of them; a point of the set
  // as x finds itself too.
  for (const int dim : {1, 2, 3}) {
    const auto x = random_points(dim, 500, 40 + dim);
    const auto queries = random_points(dim, 60, 90 + dim);
    const NeighborSearch search(x, dim);
    std::vector<std::int32_t> found;
    std::size_t total = 0;
    for (const double r : {0.0, 0.05, 0.2})
      for (std::size_t q = 0; q < queries[0].size(); ++q) {
        const double at[3] = {queries[0][q], queries[1][q], queries[2][q]};
        found.assign(2, -7);
        search.around(at, r, found);
        std::vector<std::int32_t> expected;
        for (std::size_t j = 0; j < x[0].size(); ++j) {
          double d2 = 0.0;
          for (int a = 0; a < dim; ++a) d2 += (x[a][j] - at[a]) * (x[a][j] - at[a]);
          if (d2 < r * r) expected.push_back(static_cast<std::int32_t>(j));
        }
        EXPECT_EQ(found, expected) << dim << "D q=" << q << " r=" << r;
        total += found.size();
      }
    EXPECT_GT(total, 200u) << dim;
    const double first[3] = {x[0][0], x[1][0], x[2][0]};
    search.around(first, 1e-9, found);
    EXPECT_EQ(found, std::vector<std::int32_t>{0}) << dim;
  }
}

TEST(NeighborSearch, LatticeAtAndAroundLatticeDistances) {
  // h = 1/8: the radii 2h, √5 h (as computed), 3h are lattice distances, hit exactly by many
  // pairs; the others lie just inside and outside them.
  const double h = 0.125;
  for (const int dim : {1, 2, 3}) {
    const auto x = lattice(dim, dim == 3 ? 7 : (dim == 2 ? 12 : 40), h);
    const double r5 = std::sqrt(5.0) * h;
    expect_matches_brute_force(x, dim,
                               {h, 2 * h, r5, 3 * h, 3 * h * (1 + 1e-12), 3 * h * (1 - 1e-12),
                                3.015 * h, std::nextafter(2 * h, 1.0)});
  }
}

TEST(NeighborSearch, APointExactlyAtTheRadiusIsLeftOutAndOneJustInsideIsKept) {
  const auto x = lattice(2, 5, 0.125);  // point 12 at (0.25, 0.25)
  const NeighborSearch search(x, 2);
  std::vector<std::int32_t> found;
  search.within(12, 0.125, found);  // the four nearest lie exactly at the radius
  EXPECT_TRUE(found.empty());
  search.within(12, std::nextafter(0.125, 1.0), found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{7, 11, 13, 17}));
  search.within(12, 0.0, found);
  EXPECT_TRUE(found.empty());
}

TEST(NeighborSearch, CoincidentPointsAreNeighboursButNeverTheQueryItself) {
  // Three points at one place, two elsewhere; in 3D only the first two axes differ.
  VectorArray x;
  x[0] = {0.5, 0.5, 0.5, 0.9, 0.1};
  x[1] = {0.5, 0.5, 0.5, 0.5, 0.5};
  x[2] = {0.0, 0.0, 0.0, 0.0, 0.0};
  for (const int dim : {2, 3}) {
    const NeighborSearch search(x, dim);
    std::vector<std::int32_t> found;
    search.within(1, 0.3, found);
    EXPECT_EQ(found, (std::vector<std::int32_t>{0, 2})) << dim;
    search.within(0, 0.41, found);
    EXPECT_EQ(found, (std::vector<std::int32_t>{1, 2, 3, 4})) << dim;
    expect_matches_brute_force(x, dim, {1e-300, 0.2, 0.4, 0.5});
  }
}

TEST(NeighborSearch, OnlyTheFirstDimAxesCount) {
  // Points that differ along z only: for a 2D search they coincide.
  VectorArray x;
  x[0] = {0, 0, 0};
  x[1] = {0, 0, 1};
  x[2] = {0, 5, 0};
  const NeighborSearch flat(x, 2), solid(x, 3);
  std::vector<std::int32_t> found;
  flat.within(0, 0.5, found);
  EXPECT_EQ(found, (std::vector<std::int32_t>{1}));
  solid.within(0, 0.5, found);
  EXPECT_TRUE(found.empty());
}

}  // namespace
}  // namespace dhpd
