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
double dense_largest_omega2(const InteractionList& il, const ParticleStore& p) {
  const int dim = p.dim();
  const auto n = static_cast<Eigen::Index>(p.size()) * dim;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = il.begin(i); k < il.end(i); ++k) {
      const auto o = static_cast<std::size_t>(il.other[k]);
      double e[3];
      for (int a = 0; a < dim; ++a)
        e[a] = (p.reference_position[a][o] - p.reference_position[a][i]) * il.inv_length[k];
      const double c = il.coefficient[k] * il.inv_length[k] / p.density[i];
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
  const double exact = dense_largest_omega2(a.rows, p);
  const auto power = largest_stable_step(a.rows, p);
  const double bound = critical_time_step(a.rows, p);
  std::printf("dim %d: power ω² / exact %.5f after %d iterations; bound dt / exact dt %.3f\n", dim,
              power.omega2 / exact, power.iterations, bound / (2.0 / std::sqrt(exact)));
  EXPECT_LE(power.omega2, exact * (1 + 1e-9));  // a Rayleigh quotient never overshoots
  EXPECT_GE(power.omega2, 0.97 * exact);
  EXPECT_LE(bound, 2.0 / std::sqrt(exact));  // the per-particle bound is safe
}

INSTANTIATE_TEST_SUITE_P(Dimensions, PowerStableStep, ::testing::Values(1, 2, 3));

bool stays_stable(double dt, int steps) {
  auto s = test::ringing_plate(true);
  s.fixed_dt = dt;
  Simulation sim(s);
  try {
    sim.run_steps(steps);
    sim.check_stable(sim.energies());
  } catch (const InstabilityError&) {
    return false;
  }
  return true;
}

TEST(PowerStableStepRun, RunsBelowTheEstimateStayStableAndAboveItBlowUp) {
  const Simulation sim(test::ringing_plate(true));
  const auto power = largest_stable_step(sim.interactions(), sim.particles());
  std::printf("graded plate: power dt / per-particle bound %.3f (%d iterations)\n",
              power.dt / sim.critical_dt(), power.iterations);
  EXPECT_TRUE(stays_stable(0.97 * power.dt, 4000));
  EXPECT_FALSE(stays_stable(1.05 * power.dt, 4000));
}

}  // namespace
}  // namespace dhpd
