// Pre-cracks (docs/theory.md §8): segment and planar-polygon crossing tests, against brute force.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "geometry/crack.hpp"

namespace dhpd {
namespace {

using geometry::Crack;

TEST(CrackGeometry, SegmentCrossingIn2D) {
  const Crack c{{{0, 0, 0}, {1, 0, 0}}};
  EXPECT_TRUE(geometry::crosses(c, {0.5, -1, 0}, {0.5, 1, 0}, 2));
  EXPECT_TRUE(geometry::crosses(c, {0.5, 0, 0}, {0.5, 1, 0}, 2));   // touching counts
  EXPECT_TRUE(geometry::crosses(c, {1.0, -1, 0}, {1.0, 1, 0}, 2));  // through the tip
  EXPECT_FALSE(geometry::crosses(c, {1.01, -1, 0}, {1.01, 1, 0}, 2));
  EXPECT_FALSE(geometry::crosses(c, {0.2, 0.1, 0}, {0.8, 0.5, 0}, 2));
  EXPECT_FALSE(geometry::crosses(c, {-0.5, -1, 0}, {-0.5, 1, 0}, 2));
}

TEST(CrackGeometry, QuadCrossingIn3D) {
  const Crack c{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  ASSERT_TRUE(geometry::is_planar(c));
  EXPECT_TRUE(geometry::crosses(c, {0.5, 0.5, -1}, {0.5, 0.5, 1}, 3));
  EXPECT_TRUE(geometry::crosses(c, {0.9, 0.1, -1}, {0.9, 0.1, 1}, 3));
  EXPECT_FALSE(geometry::crosses(c, {1.5, 0.5, -1}, {1.5, 0.5, 1}, 3));
  EXPECT_FALSE(geometry::crosses(c, {0.5, 0.5, 0.1}, {0.5, 0.5, 1}, 3));
  EXPECT_FALSE(geometry::crosses(c, {0.5, 0.5, 0.5}, {0.6, 0.5, 0.5}, 3));  // parallel
  const Crack bent{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0.2}, {0, 1, 0}}};
  EXPECT_FALSE(geometry::is_planar(bent));
  EXPECT_FALSE(geometry::is_planar(Crack{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}}));  // collinear
}

// A non-convex (L-shaped) planar polygon in a tilted plane, checked against a brute-force
// crossing test: where the segment meets the plane, is that point inside the L?
TEST(CrackGeometry, NonConvexPolygonIn3DMatchesBruteForce) {
  // L in the (u, v) plane: [0,2]x[0,1] ∪ [0,1]x[1,2], embedded by X = (u, v, 0.3 u + 0.2 v).
  const std::vector<std::array<double, 2>> l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  Crack c;
  for (const auto& q : l) c.points.push_back({q[0], q[1], 0.3 * q[0] + 0.2 * q[1]});
  ASSERT_TRUE(geometry::is_planar(c));
  EXPECT_TRUE(geometry::is_planar(Crack{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}));  // a triangle
  auto in_l = [](double u, double v) {
    return (u >= 0 && u <= 2 && v >= 0 && v <= 1) || (u >= 0 && u <= 1 && v >= 0 && v <= 2);
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-0.5, 2.5);
  int hits = 0, checked = 0;
  for (int k = 0; k < 4000; ++k) {
    const double u = coord(rng), v = coord(rng);
    if (std::abs(u - 1) < 1e-6 || std::abs(v - 1) < 1e-6) continue;  // skip edge ties
    const double z = 0.3 * u + 0.2 * v;
    const geometry::Vec3 a{u, v, z - 0.7}, b{u, v, z + 0.4};
    EXPECT_EQ(geometry::crosses(c, a, b, 3), in_l(u, v)) << u << ", " << v;
    hits += in_l(u, v), ++checked;
    const geometry::Vec3 above{u, v, z + 0.1};
    EXPECT_FALSE(geometry::crosses(c, above, b, 3));  // both ends on one side
  }
  EXPECT_GT(hits, checked / 5);
}

}  // namespace
}  // namespace dhpd
