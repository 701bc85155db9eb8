// Shapes: containment with the closed-set convention, bounds, unions and differences, polygon
// checks; a plate with a hole against brute force; later lattice parts win inside their shape.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "geometry/lattice.hpp"
#include "geometry/shapes.hpp"

namespace dhpd::geometry {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Shapes, BoxIsClosed) {
  const Shape box(Box{{0, 0, 0}, {2, 1, 0}});
  EXPECT_TRUE(box.contains({1, 0.5, 0}, 2));
  EXPECT_TRUE(box.contains({2, 1, 0}, 2));  // corner
  EXPECT_TRUE(box.contains({0, 0.3, 0}, 2));
  EXPECT_FALSE(box.contains({2.001, 0.5, 0}, 2));
  EXPECT_FALSE(box.contains({1, -1e-9, 0}, 2));
  EXPECT_EQ(box.bounds(2), (Box{{0, 0, 0}, {2, 1, 0}}));
}

TEST(Shapes, DiskAndSphere) {
  const Shape disk = Shape::ball({1, 1, 0}, 0.5);
  EXPECT_TRUE(disk.contains({1, 1, 0}, 2));
  EXPECT_TRUE(disk.contains({1.5, 1, 0}, 2));  // on the rim
  EXPECT_FALSE(disk.contains({1.36, 1.36, 0}, 2));
  EXPECT_FALSE(disk.contains({1.5001, 1, 0}, 2));
  EXPECT_EQ(disk.bounds(2), (Box{{0.5, 0.5, 0}, {1.5, 1.5, 0}}));
  const Shape sphere = Shape::ball({0, 0, 0}, 1);
  EXPECT_TRUE(sphere.contains({0, 0, 1}, 3));
  EXPECT_TRUE(sphere.contains({0.5, 0.5, 0.5}, 3));
  EXPECT_FALSE(sphere.contains({0.6, 0.6, 0.6}, 3));  // inside the disk of its first two axes
  EXPECT_EQ(sphere.bounds(3), (Box{{-1, -1, -1}, {1, 1, 1}}));
}

TEST(Shapes, Cylinder) {
  // The axis need not be a unit vector: the height is measured along its direction.
  const Shape c = Shape::cylinder({0, 0, 1}, {0, 0, 4}, 0.5, 2);
  EXPECT_TRUE(c.contains({0, 0, 2}, 3));
  EXPECT_TRUE(c.contains({0.5, 0, 2}, 3));  // side
  EXPECT_TRUE(c.contains({0, 0, 3}, 3));    // top
  EXPECT_TRUE(c.contains({0, 0, 1}, 3));    // base
  EXPECT_FALSE(c.contains({0, 0, 3.01}, 3));
  EXPECT_FALSE(c.contains({0, 0, 0.99}, 3));
  EXPECT_FALSE(c.contains({0.4, 0.4, 2}, 3));
  EXPECT_EQ(c.bounds(3), (Box{{-0.5, -0.5, 1}, {0.5, 0.5, 3}}));
  const Shape along_x = Shape::cylinder({1, 0, 0}, {-1, 0, 0}, 1, 3);
  EXPECT_TRUE(along_x.contains({-1.5, 0.7, 0.7}, 3));
  EXPECT_FALSE(along_x.contains({1.5, 0, 0}, 3));
  EXPECT_EQ(along_x.bounds(3), (Box{{-2, -1, -1}, {1, 1, 1}}));
}

TEST(Shapes, HalfSpace) {
  const Shape h = Shape::half_space({1, 0, 0}, {1, 0, 0});
  EXPECT_TRUE(h.contains({0.5, 7, 0}, 2));
  EXPECT_TRUE(h.contains({1, -3, 0}, 2));  // on the plane
  EXPECT_FALSE(h.contains({1.1, 0, 0}, 2));
  const Box b = h.bounds(2);
  EXPECT_EQ(b.max[0], 1.0);
  EXPECT_EQ(b.min[0], -kInf);
  EXPECT_EQ(b.max[1], kInf);
  EXPECT_FALSE(b.finite(2));
  const Shape oblique = Shape::half_space({0, 0, 0}, {1, 1, 0});
  EXPECT_TRUE(oblique.contains({1, -1, 0}, 2));
  EXPECT_FALSE(oblique.contains({1, -0.9, 0}, 2));
  EXPECT_EQ(oblique.bounds(2).max[0], kInf);
}

TEST(Shapes, UnionAndDifference) {
  const Shape a(Box{{0, 0, 0}, {1, 1, 0}});
  const Shape b(Box{{2, 0, 0}, {3, 2, 0}});
  const Shape u = Shape::union_of({a, b});
  EXPECT_TRUE(u.contains({0.5, 0.5, 0}, 2));
  EXPECT_TRUE(u.contains({2.5, 1.5, 0}, 2));
  EXPECT_FALSE(u.contains({1.5, 0.5, 0}, 2));
  EXPECT_EQ(u.bounds(2), (Box{{0, 0, 0}, {3, 2, 0}}));
  // Difference: the rim of the hole is not in the result (the hole is a closed set).
  const Shape plate =
      Shape::difference({Shape(Box{{0, 0, 0}, {4, 2, 0}}), Shape::ball({2, 1, 0}, 0.5), u});
  EXPECT_TRUE(plate.contains({3.5, 0.1, 0}, 2));
  EXPECT_FALSE(plate.contains({2, 1, 0}, 2));
  EXPECT_FALSE(plate.contains({2.5, 1, 0}, 2));
  EXPECT_FALSE(plate.contains({0.5, 0.5, 0}, 2));
  EXPECT_TRUE(plate.contains({1.5, 1.5, 0}, 2));
  EXPECT_EQ(plate.bounds(2), (Box{{0, 0, 0}, {4, 2, 0}}));
  // Nested: a difference inside a union keeps its own operands.
  const Shape nested = Shape::union_of({plate, Shape::ball({2, 1, 0}, 0.1)});
  EXPECT_TRUE(nested.contains({2, 1, 0}, 2));
  EXPECT_FALSE(nested.contains({2.3, 1, 0}, 2));
}

TEST(Shapes, ConvexAndConcavePolygons) {
  const Shape square = Shape::polygon({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_TRUE(square.contains({0.5, 0.5, 0}, 2));
  EXPECT_TRUE(square.contains({1, 0.5, 0}, 2));  // edge
  EXPECT_TRUE(square.contains({0, 0, 0}, 2));    // vertex
  EXPECT_FALSE(square.contains({1.01, 0.5, 0}, 2));
  EXPECT_EQ(square.bounds(2), (Box{{0, 0, 0}, {1, 1, 0}}));
  // An L: the notch [1, 2] × [1, 2] is outside; clockwise order works the same.
  const Shape ell =
      Shape::polygon({{0, 0, 0}, {0, 2, 0}, {1, 2, 0}, {1, 1, 0}, {2, 1, 0}, {2, 0, 0}});
  EXPECT_TRUE(ell.contains({0.5, 1.5, 0}, 2));
  EXPECT_TRUE(ell.contains({1.5, 0.5, 0}, 2));
  EXPECT_TRUE(ell.contains({1.5, 1, 0}, 2));  // the notch's edge
  EXPECT_FALSE(ell.contains({1.5, 1.5, 0}, 2));
  EXPECT_FALSE(ell.contains({1.01, 1.01, 0}, 2));
  EXPECT_EQ(polygon_self_intersection(ell.node(ell.root()).points), std::nullopt);
}

TEST(Shapes, SelfIntersectionIsDetected) {
  using Edges = std::optional<std::pair<int, int>>;
  EXPECT_EQ(polygon_self_intersection({{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}}),
            (Edges{{0, 2}}));  // bow tie
  EXPECT_EQ(polygon_self_intersection({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}), std::nullopt);
  // A vertex touching another edge.
  EXPECT_EQ(polygon_self_intersection({{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {1, 0, 0}, {0, 2, 0}}),
            (Edges{{0, 2}}));  // point 3 lies on edge 0
  // Collinear points folding back on themselves.
  EXPECT_EQ(polygon_self_intersection({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {1, 1, 0}}),
            (Edges{{0, 1}}));
  // Collinear and flat: the closing edge overlaps the first.
  EXPECT_EQ(polygon_self_intersection({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}), (Edges{{0, 2}}));
}

TEST(Shapes, PlateWithHoleMatchesBruteForce) {
  const Box plate{{0, 0, 0}, {0.1, 0.04, 0}};
  const Vec3 centre{0.05, 0.02, 0};
  const double r = 0.0105, h = 1e-3;
  const auto pts =
      fill_lattice({{Shape::difference({Shape(plate), Shape::ball(centre, r)}), h, 0}}, 2);
  std::size_t expected = 0;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 100; ++i) {
      const double x = (i + 0.5) * h, y = (j + 0.5) * h;
      expected += (x - centre[0]) * (x - centre[0]) + (y - centre[1]) * (y - centre[1]) > r * r;
    }
  EXPECT_EQ(pts.size(), expected);
  EXPECT_EQ(pts.size(), 3668u);
  EXPECT_LT(pts.size(), 4000u - 300u);  // about π r² / h² = 346 points removed
  for (const auto& x : pts.position) EXPECT_GT(norm(x - centre), r);
}

TEST(Shapes, LaterPartWinsInsideItsShapeOnly) {
  // A fine disk over a coarse box: coarse points inside the disk go, those in the disk's bounding
  // box but outside the disk stay.
  const Shape disk = Shape::ball({0.5, 0.5, 0}, 0.2);
  const auto pts = fill_lattice({{Box{{0, 0, 0}, {1, 1, 0}}, 0.1, 0}, {disk, 0.02, 1}}, 2);
  std::size_t coarse = 0, fine = 0, coarse_kept_in_bounds = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const bool in_disk = disk.contains(pts.position[i], 2);
    if (pts.part[i] == 0) {
      ++coarse;
      EXPECT_FALSE(in_disk);
      coarse_kept_in_bounds += disk.bounds(2).contains(pts.position[i], 2);
    } else {
      ++fine;
      EXPECT_TRUE(in_disk);
    }
  }
  std::size_t expected_coarse = 0;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i)
      expected_coarse += !disk.contains({(i + 0.5) * 0.1, (j + 0.5) * 0.1, 0}, 2);
  EXPECT_EQ(coarse, expected_coarse);
  EXPECT_GT(coarse_kept_in_bounds, 0u);
  EXPECT_GT(fine, 300u);  // π 0.2² / 0.02² ≈ 314
}

}  // namespace
}  // namespace dhpd::geometry
