// The power-iteration estimate of the largest stable step (docs/theory.md §9): against a dense
// eigen-solve of the same linearised stiffness, and against runs just below and above it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>

#include "engine/base/errors.hpp"
#include "engine/physics/stable_step.hpp"
#include "tests/support/engine.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

/// The largest eigenvalue of M⁻¹K assembled densely from the rows (reference directions).
double dense_largest_omega2(const BondRows& il, const ParticleStore& p) {
  const int dim = p.dim();
  const auto n = static_cast<Eigen::Index>(p.size()) * dim;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = il.begin(i); k < il.end(i); ++k) {
      const auto o = static_cast<std::size_t>(il.other[k]);
      double e[3];
      for (int a = 0; a < dim; ++a)
        e[a] = (p.reference_position[a][o] - p.reference_position[a][i]) * il.inverse_length(k);
      const double c = static_cast<double>(il.stiffness[k]) * il.stiffness_scale * p.volume[o] *
                       il.inverse_length(k) / p.density[i];
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          const auto row = static_cast<Eigen::Index>(i) * dim + a;
          A(row, static_cast<Eigen::Index>(o) * dim + b) -= c * e[a] * e[b];
          A(row, static_cast<Eigen::Index>(i) * dim + b) += c * e[a] * e[b];
        }
    }
  return Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues().real().maxCoeff();
}

class PowerStableStep : public ::testing::TestWithParam<int> {};

TEST_P(PowerStableStep, PowerIterationFindsTheLargestEigenvalue) {
  const int dim = GetParam();
  const std::size_t n = dim == 1 ? 120 : (dim == 2 ? 150 : 90);
  const auto p = test::random_cloud(dim, n, dim == 1 ? 0.01 : 0.1, 3.0, 3.015, 11 + dim);
  Section s;
  s.dim = dim;
  const auto a =
      test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear, {1e9, 1000, 1.0}, s);
  const double exact = dense_largest_omega2(a.bonds, p);
  const auto power = largest_stable_step(a.bonds, p);
  const double bound = critical_time_step(a.bonds, p);
  std::printf("dim %d: power ω² / exact %.5f after %d iterations; bound dt / exact dt %.3f\n", dim,
              power.omega2 / exact, power.iterations, bound / (2.0 / std::sqrt(exact)));
  EXPECT_LE(power.omega2, exact * (1 + 1e-9));  // a Rayleigh quotient never overshoots
  EXPECT_GE(power.omega2, 0.97 * exact);
  EXPECT_LE(bound, 2.0 / std::sqrt(exact));  // the per-particle bound is safe
  const auto lanczos = lanczos_stable_step(a.bonds, p);
  std::printf("dim %d: Lanczos ω² / exact %.7f after %d iterations\n", dim, lanczos.omega2 / exact,
              lanczos.iterations);
  EXPECT_LE(lanczos.omega2, exact * (1 + 1e-9));  // a Ritz value never overshoots
  EXPECT_GE(lanczos.omega2, 0.995 * exact);
  EXPECT_LT(lanczos.iterations, power.iterations);
}

INSTANTIATE_TEST_SUITE_P(Dimensions, PowerStableStep, ::testing::Values(1, 2, 3));

SimulationSetup plane_strain_plate() {
  auto s = test::ringing_plate(false);
  s.section.plane = PlaneMode::Strain;
  return s;
}

struct LimitCase {
  const char* name;
  SimulationSetup (*setup)();
};

class StableStepLimit : public ::testing::TestWithParam<LimitCase> {};

// The run's automatic step (Lanczos, docs/theory.md §9) against the limit found by bisection on a
// fixed dt: 2/ω of a Ritz value is at or just above the limit, never 15 % off; the per-particle
// bound (9.1) is printed beside it (0.6–0.9 of the limit).
TEST_P(StableStepLimit, TheEstimateIsWithinOnePercentOfTheMeasuredLimit) {
  auto s = GetParam().setup();
  s.stable_step = StableStepEstimate::Lanczos;
  const Simulation sim(s);
  const double estimate = sim.critical_dt();
  auto bound_setup = s;
  bound_setup.stable_step = StableStepEstimate::ParticleBound;
  const double bound = Simulation(bound_setup).critical_dt();
  const double limit = test::measured_limit(s, 0.8 * estimate, 1.2 * estimate);
  std::printf("%s: measured limit / Lanczos estimate %.4f, per-particle bound / limit %.3f\n",
              GetParam().name, limit / estimate, bound / limit);
  EXPECT_GE(limit / estimate, 0.99);
  EXPECT_LE(limit / estimate, 1.005);  // a Ritz value: 2/ω at or above the limit
  EXPECT_LT(bound, limit);             // the bound stays safe
}

INSTANTIATE_TEST_SUITE_P(
    Bodies, StableStepLimit,
    ::testing::Values(LimitCase{"bar_1d", [] { return test::pulsed_bar_1d(); }},
                      LimitCase{"plate_plane_stress", [] { return test::ringing_plate(false); }},
                      LimitCase{"plate_plane_strain", plane_strain_plate},
                      LimitCase{"block_3d", [] { return test::pulsed_block_3d(); }},
                      LimitCase{"graded_plate", [] { return test::ringing_plate(true); }}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace dhpd
