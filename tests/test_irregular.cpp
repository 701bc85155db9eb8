// Irregular point sets (issue 3; CMAME 2017 §6): meshed parts, their volumes, momentum balance and
// strain energy of dual-horizon PD on them, and a meshed part run from a scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "geometry/mesh_points.hpp"
#include "tests/support.hpp"
#include "tools/scene.hpp"
#include "tools/scene_build.hpp"

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
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_GT(pts.cell_measure[i], 0.0) << i;
    EXPECT_DOUBLE_EQ(pts.spacing[i], std::sqrt(pts.cell_measure[i])) << i;
    EXPECT_EQ(pts.material[i], 3);
    EXPECT_EQ(pts.part[i], 5);
  }
  // Every edge is at most `size` long, so an interior node's share stays below a lattice cell of
  // that size and well above zero.
  const double largest = *std::max_element(pts.spacing.begin(), pts.spacing.end());
  EXPECT_LE(largest, 0.004);
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
  EXPECT_THROW(geometry::mesh_box(plate(1, 1), 3, MeshSize{0.1}, 0), std::invalid_argument);
  EXPECT_THROW(geometry::mesh_polygon({{0, 0}, {1, 0}}, MeshSize{0.1}, 0), std::invalid_argument);
}

TEST(IrregularMomentum, DualHorizonBalancesOnAGradedMesh) {
  const auto pts = geometry::mesh_box(plate(0.1, 0.1), 2, MeshSize{0.003, 0.1, {0.02, 0.03, 0}}, 0);
  Section s;
  s.dim = 2;
  s.thickness = 1e-3;
  auto p = test::store_from_points(pts, 2, 3.015, s);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1e-5, 1e-5);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 2; ++a) test::set_displacement(p, a, i, u(rng));
  const Material m{70e9, 2700, 1.0};
  for (const auto pv : {PartialVolume::None, PartialVolume::Linear}) {
    auto q = p;
    auto dh = test::assemble(q, ForceModel::DualHorizon, pv, m, s);
    internal_force_density(dh.rows, q);
    const auto b = test::momentum_balance(q);
    auto r = p;
    auto cv = test::assemble(r, ForceModel::ClassicalVariable, pv, m, s);
    internal_force_density(cv.rows, r);
    const auto c = test::momentum_balance(r);
    std::printf(
        "mesh %zu nodes, %s: DH-PD |ΣF|/Σ|F| = %.2e, |ΣM|/Σ|M| = %.2e; classical-variable "
        "%.2e, %.2e\n",
        p.size(), pv == PartialVolume::None ? "none" : "linear", b.linear, b.angular, c.linear,
        c.angular);
    EXPECT_LT(b.linear, 1e-12);
    EXPECT_LT(b.angular, 1e-12);
    EXPECT_GT(c.linear, 1e4 * std::max(b.linear, 1e-18));  // the test can tell the difference
  }
}

}  // namespace
}  // namespace dhpd
