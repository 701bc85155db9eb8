// Correspondence (non-ordinary state-based) DH-PD, small-strain elastic (docs/theory.md §21): the
// deformation gradient and Hooke's energy of a uniform strain, no force inside a strained body,
// forces as the energy's gradient, momentum with horizons varying 10×, and the zero-energy modes
// the stabilisation removes.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "engine/physics/correspondence.hpp"
#include "tests/support/checkpoint.hpp"
#include "tests/support/engine.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::section_of;

struct Model {
  BondRows bonds;
  std::vector<Material> materials;
  Correspondence model;
};

Model assemble(const ParticleStore& p, const Section& s, double stabilisation = kStabilisation,
               ForceModel horizon = ForceModel::DualHorizon) {
  Model m;
  m.bonds = build_bond_rows(p, PartialVolume::Linear, {});
  m.materials = {{2e9, 1000.0, 0.0, s.dim == 1 ? std::nan("") : 0.3}};
  m.model = Correspondence(
      m.bonds, p, {s, horizon, PartialVolume::Linear, Influence::Constant, &m.materials, false},
      stabilisation);
  return m;
}

TEST(Correspondence, ForceIsTheEnergysGradient) {
  for (const int dim : {1, 2, 3}) {
    const auto s = section_of(dim);
    auto p = test::random_cloud(dim, 150, dim == 3 ? 0.06 : 0.03, 4.0, 3.015, 3 + dim);
    auto m = assemble(p, s);
    m.model.forces(m.bonds, p);
    const auto f = p.force_density;
    double worst = 0.0;
    for (const std::size_t i : {std::size_t{5}, std::size_t{60}, std::size_t{120}})
      for (int a = 0; a < dim; ++a) {
        const double h = 1e-8, u0 = p.displacement[a][i];
        test::set_displacement(p, a, i, u0 + h);
        const double up = m.model.strain_energy(m.bonds, p);
        test::set_displacement(p, a, i, u0 - h);
        const double down = m.model.strain_energy(m.bonds, p);
        test::set_displacement(p, a, i, u0);
        const double force = f[a][i] * p.volume[i];
        worst = std::max(worst, std::abs(force + (up - down) / (2 * h)) / std::abs(force));
      }
    std::printf("%dD: |F + ∂U/∂u| ≤ %.2e of |F|\n", dim, worst);
    EXPECT_LT(worst, 1e-5);
  }
}

// A uniform strain: every particle's H is the strain whatever its neighbourhood (K⁻¹ uses the same
// sums), so W is Hooke's everywhere, edges included, and no force acts inside.
TEST(Correspondence, UniformStrainIsExactEverywhere) {
  for (const int dim : {1, 2, 3}) {
    const auto s = section_of(dim);
    const int cells = dim == 1 ? 30 : (dim == 2 ? 20 : 12);
    const double dx = 1e-3, L = cells * dx, delta = 2.015 * dx, e0 = 1e-6;
    auto p = test::lattice_store(dim, cells, dx, 2.015, s);
    const double eps[3][3] = {{e0, 0.4 * e0, -0.2 * e0},
                              {0.4 * e0, -0.3 * e0, 0.5 * e0},
                              {-0.2 * e0, 0.5 * e0, 0.7 * e0}};
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int a = 0; a < dim; ++a) {
        double u = 0.0;
        for (int b = 0; b < dim; ++b) u += eps[a][b] * p.reference_position[b][i];
        test::set_displacement(p, a, i, u);
      }
    auto m = assemble(p, s);
    m.model.forces(m.bonds, p);
    // Hooke's energy density of the dimension (1D: E ε²/2).
    const double E = 2e9, nu = 0.3, mu = E / (2 * (1 + nu));
    const double lambda = dim == 1 ? E : E * nu / ((1 + nu) * (1 - 2 * nu));
    double tr = 0.0, ee = 0.0;
    for (int a = 0; a < dim; ++a) tr += eps[a][a];
    for (int a = 0; a < dim; ++a)
      for (int b = 0; b < dim; ++b) ee += eps[a][b] * eps[a][b];
    const double w = dim == 1 ? 0.5 * E * e0 * e0 : 0.5 * lambda * tr * tr + mu * ee;
    double volume = 0.0, force = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      volume += p.volume[i];
      bool inside = true;
      for (int a = 0; a < dim; ++a)
        inside = inside && p.reference_position[a][i] > 2 * delta + dx &&
                 p.reference_position[a][i] < L - 2 * delta - dx;
      if (inside)
        for (int a = 0; a < dim; ++a) force = std::max(force, std::abs(p.force_density[a][i]));
    }
    const double energy = m.model.strain_energy(m.bonds, p) / volume;
    std::printf("%dD: W / Hooke's = %.12f, largest force inside %.2e of E ε/Δx\n", dim, energy / w,
                force / (E * e0 / dx));
    EXPECT_NEAR(energy / w, 1.0, 1e-9);
    EXPECT_LT(force, 1e-8 * E * e0 / dx);
  }
}

// Linear momentum to round-off with horizons varying 10× (each bond's force on both ends).
TEST(Correspondence, MomentumIsExactWithHorizonsVaryingTenfold) {
  for (const int dim : {1, 2, 3}) {
    auto p = test::random_cloud(dim, dim == 3 ? 500 : 400, dim == 3 ? 0.04 : 0.02, 10.0, 3.015,
                                30 + dim);
    auto m = assemble(p, section_of(dim));
    m.model.forces(m.bonds, p);
    const auto current = test::momentum_balance(p);
    // A small-strain model balances moments about the reference configuration (its forces are
    // linear in u); about the current one only to the order of the strain.
    auto q = p;
    for (int a = 0; a < 3; ++a) q.position[a] = q.reference_position[a];
    const auto b = test::momentum_balance(q);
    std::printf("%dD: |ΣF|/Σ|F| = %.2e, |ΣX×F|/Σ|X||F| = %.2e (about the current positions %.2e)\n",
                dim, b.linear, b.angular, current.angular);
    EXPECT_LT(b.linear, 1e-12);
    EXPECT_LT(b.angular, 1e-12);
  }
}

// The spectrum of a small plate (dense): the stabilisation lifts the softest deformation modes
// that the correspondence force barely resists; rigid motions stay the only zero modes.
TEST(Correspondence, StabilisationLiftsTheSoftestModes) {
  const auto s = section_of(2);
  auto p = test::lattice_store(2, 10, 1e-3, 2.015, s);
  double softest[2] = {0, 0};
  int zeros[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto m = assemble(p, s, k == 0 ? 0.0 : kStabilisation);
    const auto N = static_cast<Eigen::Index>(2 * p.size());
    Eigen::MatrixXd A(N, N);
    std::vector<double> u(static_cast<std::size_t>(N)), out;
    for (Eigen::Index c = 0; c < N; ++c) {
      std::fill(u.begin(), u.end(), 0.0);
      u[static_cast<std::size_t>(c)] = 1.0;
      m.model.stiffness_times(m.bonds, p, u, out);
      for (Eigen::Index r = 0; r < N; ++r) A(r, c) = out[static_cast<std::size_t>(r)];
    }
    Eigen::VectorXd ev = Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues().real();
    std::sort(ev.data(), ev.data() + N);
    for (Eigen::Index r = 0; r < N; ++r) zeros[k] += std::abs(ev[r]) < 1e-9 * ev[N - 1] ? 1 : 0;
    softest[k] = ev[3] / ev[N - 1];
  }
  std::printf(
      "zero modes %d / %d; softest deformation mode / stiffest %.2e without, %.2e with the "
      "stabilisation\n",
      zeros[0], zeros[1], softest[0], softest[1]);
  EXPECT_EQ(zeros[1], 3);  // the plane's two translations and rotation
  EXPECT_GT(softest[1], 2 * softest[0]);
}

SimulationSetup correspondence_plate() {
  auto s = test::ringing_plate(true);
  s.family = ModelFamily::Correspondence;
  s.interface_correction = false;
  s.horizon_factor = 2.015;
  for (auto& m : s.materials) m.nu = 0.3;
  return s;
}

TEST(Correspondence, StableStepEnergyRestartsAndThreads) {
  const auto s = correspondence_plate();
  const double estimate = Simulation(s).critical_dt();
  const double limit = test::measured_limit(s, 0.8 * estimate, 1.2 * estimate);
  std::printf("measured limit / Lanczos estimate %.4f\n", limit / estimate);
  EXPECT_GE(limit / estimate, 0.99);
  EXPECT_LE(limit / estimate, 1.005);
  auto run = s;
  run.safety = 0.9;
  Simulation whole(run);
  const auto e0 = whole.energies();
  const double start = e0.kinetic + e0.strain - e0.verlet_correction;
  whole.run_steps(2000);
  const auto e = whole.energies();
  const double drift = std::abs(e.kinetic + e.strain - e.verlet_correction - start) / start;
  std::printf("shadow energy drift %.2e over 2000 steps at safety 0.9\n", drift);
  EXPECT_LT(drift, 1e-4);
  Simulation whole_short(run);
  whole_short.run_steps(200);
  test::expect_restart_and_one_thread_exact(run, whole_short, 120, 80);
}

}  // namespace
}  // namespace dhpd
