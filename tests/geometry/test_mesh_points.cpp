// Meshed parts (issue 3; CMAME 2017 §6): triangle and tetrahedral meshes turned into points, their
// volumes, grading and the sizes they refuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "geometry/mesh_points.hpp"

namespace dhpd {
namespace {

using geometry::MeshSize;

geometry::Box plate(double lx, double ly) {
  geometry::Box box;
  box.max = {lx, ly, 0};
  return box;
}

double total(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0);
}

TEST(MeshPoints, UniformPlateVolumesSumToTheAreaAndArePositive) {
  const auto pts = geometry::mesh_box(plate(0.1, 0.04), 2, MeshSize{0.004}, 3, 5);
  ASSERT_GT(pts.size(), 200u);
  EXPECT_NEAR(total(pts.cell_measure) / (0.1 * 0.04), 1.0, 1e-10);
  // Δx is the equivalent diameter (CMAME 2017 §6); cell-side is sqrt(area) on the same mesh.
  const auto cells =
      geometry::mesh_box(plate(0.1, 0.04), 2, MeshSize{0.004}, 3, 5, geometry::PointSize::CellSide);
  ASSERT_EQ(cells.size(), pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_GT(pts.cell_measure[i], 0.0) << i;
    EXPECT_DOUBLE_EQ(pts.spacing[i], 2.0 * std::sqrt(pts.cell_measure[i] / std::numbers::pi)) << i;
    EXPECT_DOUBLE_EQ(cells.spacing[i], std::sqrt(cells.cell_measure[i])) << i;
    EXPECT_EQ(pts.material[i], 3);
    EXPECT_EQ(pts.part[i], 5);
  }
  // Every edge is at most h = `size` long and the triangles around a node span at most 2π, so a
  // node's area is at most Σ ½h² sin θ_k / 3 <= πh²/3: its equivalent diameter is at most
  // 2h/√3 = 1.155 h (and well above zero).
  const double largest = *std::max_element(pts.spacing.begin(), pts.spacing.end());
  EXPECT_LE(largest, 2.0 / std::sqrt(3.0) * 0.004);
  EXPECT_GT(largest, 0.002);
}

TEST(MeshPoints, GradingCoarsensAwayFromItsOrigin) {
  MeshSize size{0.002, 0.2, {0, 0, 0}};
  const auto pts = geometry::mesh_box(plate(0.1, 0.1), 2, size, 0);
  EXPECT_NEAR(total(pts.cell_measure) / 0.01, 1.0, 1e-10);
  double near = 0, far = 0;
  int n_near = 0, n_far = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double r = geometry::norm(pts.position[i]);
    if (r < 0.02) near += pts.spacing[i], ++n_near;
    if (r > 0.12) far += pts.spacing[i], ++n_far;
  }
  ASSERT_GT(n_near, 0);
  ASSERT_GT(n_far, 0);
  std::printf("graded mesh: %zu nodes, mean spacing near the origin %.3g, far %.3g\n", pts.size(),
              near / n_near, far / n_far);
  EXPECT_GT(far / n_far, 4.0 * near / n_near);  // h grows from 0.002 to about 0.03
}

TEST(MeshPoints, NonConvexPolygonKeepsOnlyItsOwnArea) {
  // An L-shape: the unit square without its upper-right quarter (area 0.75).
  const std::vector<std::array<double, 2>> l{{0, 0},     {1, 0},   {1, 0.5},
                                             {0.5, 0.5}, {0.5, 1}, {0, 1}};
  const auto pts = geometry::mesh_polygon(l, MeshSize{0.05}, 0);
  EXPECT_NEAR(total(pts.cell_measure) / 0.75, 1.0, 1e-10);
  for (const auto& x : pts.position) EXPECT_FALSE(x[0] > 0.5 + 1e-12 && x[1] > 0.5 + 1e-12);
}

TEST(MeshPoints, RefusesWhatItCannotMesh) {
  EXPECT_THROW(geometry::mesh_box(plate(1, 1), 2, MeshSize{0.0}, 0), std::invalid_argument);
  EXPECT_THROW(geometry::mesh_box(plate(1, 1), 1, MeshSize{0.1}, 0), std::invalid_argument);
  EXPECT_THROW(geometry::mesh_box_3d(plate(1, 1), MeshSize{-1}, 0), std::invalid_argument);
  EXPECT_THROW(geometry::mesh_polygon({{0, 0}, {1, 0}}, MeshSize{0.1}, 0), std::invalid_argument);
}

geometry::Box brick() {
  geometry::Box box;
  box.min = {-0.1, 0, 0};
  box.max = {0.2, 0.2, 0.1};
  return box;
}

TEST(MeshPoints, TetrahedraFillTheBoxExactly) {
  const auto pts = geometry::mesh_box(brick(), 3, MeshSize{0.02}, 2, 1);
  ASSERT_GT(pts.size(), 300u);
  EXPECT_NEAR(total(pts.cell_measure) / brick().measure(3), 1.0, 1e-10);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_GT(pts.cell_measure[i], 0.0) << i;
    EXPECT_DOUBLE_EQ(pts.spacing[i], std::cbrt(6.0 * pts.cell_measure[i] / std::numbers::pi)) << i;
    EXPECT_TRUE(brick().contains(pts.position[i], 3)) << i;
  }
  std::printf("3D mesh: %zu nodes, spacing %.3g to %.3g\n", pts.size(),
              *std::min_element(pts.spacing.begin(), pts.spacing.end()),
              *std::max_element(pts.spacing.begin(), pts.spacing.end()));
}
}  // namespace
}  // namespace dhpd
