// Dual-horizon forces conserve linear and angular momentum for any horizons (CMAME 2017 §3);
// classical BB-PD with variable horizons does not (ghost forces, IJNME 2016 §3.2).
#include <gtest/gtest.h>

#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using test::Balance;

Balance forces_of(ParticleStore p, ForceModel model, int dim) {
  Section s;
  s.dim = dim;
  const Material m{1e9, 1000, 1.0};
  auto a = test::assemble(p, model, PartialVolume::Linear, m, s);
  internal_force_density(a.bonds, p);
  return test::momentum_balance(p);
}

class MomentumTest : public ::testing::TestWithParam<int> {};

TEST_P(MomentumTest, DualHorizonBalancesAndClassicalVariableDoesNot) {
  const int dim = GetParam();
  const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 600 : 700);
  const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.01 : 0.03);
  const auto cloud = test::random_cloud(dim, n, h, 10.0, 3.015, 42 + dim);
  const auto dh = forces_of(cloud, ForceModel::DualHorizon, dim);
  const auto cv = forces_of(cloud, ForceModel::ClassicalVariable, dim);
  std::printf("dim %d: DH-PD |ΣF|/Σ|F| = %.3e, |ΣM|/Σ|M| = %.3e; classical-variable %.3e, %.3e\n",
              dim, dh.linear, dh.angular, cv.linear, cv.angular);
  EXPECT_LT(dh.linear, 1e-12);
  EXPECT_LT(dh.angular, 1e-12);
  EXPECT_GT(cv.linear, 1e6 * std::max(dh.linear, 1e-18));
  if (dim > 1) {
    EXPECT_GT(cv.angular, 1e6 * std::max(dh.angular, 1e-18));
  }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, MomentumTest, ::testing::Values(1, 2, 3));

// Scatter reference: compute each bond once and add it to both ends (docs/theory.md §4). The rows
// store each pair's stiffness in single precision (§18), so the two agree to 2⁻²⁴ of each bond's
// force; a structural error (a dual part missing or counted twice) is off by tens of percent.
TEST(GatherVersusScatter, SameForcesOnVaryingHorizons) {
  for (int dim : {2, 3}) {
    auto p = test::random_cloud(dim, 400, dim == 2 ? 0.01 : 0.03, 10.0, 3.015, 7);
    Section s;
    s.dim = dim;
    const Material m{2e9, 1000, 1.0};
    auto a = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear, m, s);
    internal_force_density(a.bonds, p);
    std::vector<double> ref[3];
    for (auto& r : ref) r.assign(p.size(), 0.0);
    double scale = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for_each_own_bond(a.bonds, i, [&](std::int64_t b, std::size_t j) {
        double d[3], l = 0;
        for (int k = 0; k < 3; ++k) d[k] = p.position[k][j] - p.position[k][i], l += d[k] * d[k];
        l = std::sqrt(l);
        const double length =
            std::sqrt(std::pow(p.reference_position[0][j] - p.reference_position[0][i], 2) +
                      std::pow(p.reference_position[1][j] - p.reference_position[1][i], 2) +
                      std::pow(p.reference_position[2][j] - p.reference_position[2][i], 2));
        const double stretch = (l - length) / length;
        const double beta = bond_weight(p, PartialVolume::Linear, i, j, length);
        const double f = a.C[i] * stretch * beta / l;  // per volume²
        for (int k = 0; k < 3; ++k) {
          ref[k][i] += f * d[k] * p.volume[j];
          ref[k][j] -= f * d[k] * p.volume[i];
        }
        (void)b;
      });
    double err = 0;
    for (int k = 0; k < 3; ++k)
      for (std::size_t i = 0; i < p.size(); ++i) {
        err = std::max(err, std::abs(ref[k][i] - p.force_density[k][i]));
        scale = std::max(scale, std::abs(ref[k][i]));
      }
    EXPECT_LT(err, 1e-7 * scale) << "dim " << dim;
  }
}

TEST(EqualHorizons, DualHorizonEqualsConstantHorizon) {
  for (int dim : {1, 2, 3}) {
    Section s;
    s.dim = dim;
    const int cells = dim == 1 ? 60 : (dim == 2 ? 24 : 10);
    auto p = test::lattice_store(dim, cells, 1e-3, 3.015, s);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1e-6, 1e-6);
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int a = 0; a < dim; ++a) test::set_displacement(p, a, i, u(rng));
    const Material m{70e9, 2700, 1.0};
    auto q = p;
    auto dh = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear, m, s);
    auto ch = test::assemble(q, ForceModel::ConstantHorizon, PartialVolume::Linear, m, s);
    internal_force_density(dh.bonds, p);
    internal_force_density(ch.bonds, q);
    double err = 0, scale = 0;
    for (int a = 0; a < dim; ++a)
      for (std::size_t i = 0; i < p.size(); ++i) {
        err = std::max(err, std::abs(p.force_density[a][i] - q.force_density[a][i]));
        scale = std::max(scale, std::abs(q.force_density[a][i]));
      }
    EXPECT_GT(scale, 0.0);
    EXPECT_LT(err, 1e-12 * scale) << "dim " << dim;
  }
}

}  // namespace
}  // namespace dhpd
