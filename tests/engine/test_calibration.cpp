// Calibration of C(δ) and s0(δ) (docs/theory.md §6; IJNME 2016 §3.3): strain energy under uniform
// isotropic strain, fracture energy identities, and the stable time step (docs/theory.md §9).
#include <gtest/gtest.h>

#include <numbers>

#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

constexpr double pi = std::numbers::pi;

struct Config {
  int dim;
  PlaneMode plane;
  PartialVolume pv;
  double expected_ratio;  ///< lattice quadrature ratio quoted in the issue (m = 3.015)
};

/// Continuum strain-energy density for an isotropic strain ε on every axis (ν fixed by BB-PD).
double continuum_energy(const Config& c, double E, double eps) {
  if (c.dim == 1) return 0.5 * E * eps * eps;
  if (c.dim == 3) return 3.0 * E * eps * eps;  // (9/2) K ε², K = E / (3 (1 − 2ν)), ν = 1/4
  return c.plane == PlaneMode::Stress ? 1.5 * E * eps * eps   // E ε² / (1 − ν), ν = 1/3
                                      : 1.6 * E * eps * eps;  // 2 (λ + μ) ε², ν = 1/4
}

/// Σ_j β_j |ξ_j| V_j / ∫_H |ξ| dV over lattice offsets, computed without the engine.
double quadrature_ratio(const Config& c, double dx, double delta, const Section& s) {
  const int r = static_cast<int>(std::ceil(delta / dx)) + 1;
  double sum = 0.0;
  const int ry = c.dim > 1 ? r : 0, rz = c.dim > 2 ? r : 0;
  for (int k = -rz; k <= rz; ++k)
    for (int j = -ry; j <= ry; ++j)
      for (int i = -r; i <= r; ++i) {
        if (i == 0 && j == 0 && k == 0) continue;
        const double d = dx * std::sqrt(double(i * i + j * j + k * k));
        double beta = d <= delta ? 1.0 : 0.0;
        if (c.pv == PartialVolume::Linear && d <= delta && d > delta - dx / 2)
          beta = (delta + dx / 2 - d) / dx;
        sum += beta * d * s.volume_of_cell(std::pow(dx, c.dim));
      }
  const double exact = c.dim == 1   ? s.area * delta * delta
                       : c.dim == 2 ? s.thickness * 2.0 * pi * std::pow(delta, 3) / 3.0
                                    : pi * std::pow(delta, 4);
  return sum / exact;
}

class Calibration : public ::testing::TestWithParam<Config> {};

TEST_P(Calibration, InteriorEnergyMatchesContinuumTimesQuadrature) {
  const auto c = GetParam();
  Section s;
  s.dim = c.dim;
  s.plane = c.plane;
  s.thickness = 2e-3;
  s.area = 3e-4;
  const int cells = c.dim == 1 ? 41 : (c.dim == 2 ? 21 : 13);
  const double dx = 1e-3, eps = 1e-4, E = 70e9;
  auto p = test::lattice_store(c.dim, cells, dx, 3.015, s);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < c.dim; ++a)
      test::set_displacement(p, a, i, eps * p.reference_position[a][i]);
  const Material m{E, 2400, 1.0};
  auto asm_ = test::assemble(p, ForceModel::DualHorizon, c.pv, m, s);
  std::vector<double> w;
  strain_energy_density(asm_.bonds, asm_.constants(p), w);
  // The centre particle (odd cell count: exactly at the middle) is interior.
  std::size_t centre = 0;
  double best = 1e9;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d = 0;
    for (int a = 0; a < c.dim; ++a) d += std::pow(p.reference_position[a][i] - cells * dx / 2, 2);
    if (d < best) best = d, centre = i;
  }
  const double ratio = quadrature_ratio(c, dx, 3.015 * dx, s);
  const double expected = continuum_energy(c, E, eps) * ratio;
  std::printf("%dD %s %s: quadrature ratio %.4f, W/W_continuum = %.6f\n", c.dim,
              c.plane == PlaneMode::Stress ? "stress" : "strain",
              c.pv == PartialVolume::None ? "none" : "linear", ratio,
              w[centre] / continuum_energy(c, E, eps));
  EXPECT_NEAR(w[centre] / expected, 1.0, 1e-10);
  if (c.expected_ratio > 0) {
    EXPECT_NEAR(ratio, c.expected_ratio, 0.005);
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllSections, Calibration,
    ::testing::Values(Config{1, PlaneMode::Stress, PartialVolume::None, 0},
                      Config{1, PlaneMode::Stress, PartialVolume::Linear, 0},
                      Config{2, PlaneMode::Stress, PartialVolume::None, 1.025},
                      Config{2, PlaneMode::Stress, PartialVolume::Linear, 0.862},
                      Config{2, PlaneMode::Strain, PartialVolume::None, 1.025},
                      Config{2, PlaneMode::Strain, PartialVolume::Linear, 0.862},
                      Config{3, PlaneMode::Stress, PartialVolume::None, 1.099},
                      Config{3, PlaneMode::Stress, PartialVolume::Linear, 0.890}));

TEST(MaterialLaw, MicromodulusMatchesClosedForms) {
  const Material m{72e9, 2440, 3.8};
  const double d = 3.015e-3, h = 2e-3, A = 5e-5;
  Section s3{3, PlaneMode::Stress, 1, 1}, ps{2, PlaneMode::Stress, h, 1},
      pe{2, PlaneMode::Strain, h, 1}, s1{1, PlaneMode::Stress, 1, A};
  auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
  const double nu3 = 0.25, nus = 1.0 / 3.0;
  EXPECT_LT(rel(micromodulus(m, s3, d), 3 * m.E / (pi * std::pow(d, 4) * (1 - 2 * nu3))), 1e-12);
  EXPECT_LT(rel(micromodulus(m, ps, d), 3 * m.E / (pi * h * std::pow(d, 3) * (1 - nus))), 1e-12);
  EXPECT_LT(
      rel(micromodulus(m, pe, d), 3 * m.E / (pi * h * std::pow(d, 3) * (1 + nu3) * (1 - 2 * nu3))),
      1e-12);
  EXPECT_LT(rel(micromodulus(m, s1, d), m.E / (A * d * d)), 1e-12);
  EXPECT_EQ(implied_poisson_ratio(ps), 1.0 / 3.0);
  EXPECT_EQ(implied_poisson_ratio(pe), 0.25);
  EXPECT_EQ(implied_poisson_ratio(s3), 0.25);
}

// G0 is the energy per crack area of all bonds crossing a plane at s0 (classical c = 2C):
// 3D G0 = π c s0² δ⁵ / 10, 2D G0 = c s0² h δ⁴ / 4, 1D G0 = A c s0² δ³ / 6.
TEST(MaterialLaw, CriticalStretchReleasesG0) {
  const Material m{72e9, 2440, 3.8};
  const double d = 3.015e-3, h = 2e-3, A = 5e-5;
  Section s3{3, PlaneMode::Stress, 1, 1}, ps{2, PlaneMode::Stress, h, 1},
      pe{2, PlaneMode::Strain, h, 1}, s1{1, PlaneMode::Stress, 1, A};
  auto g = [&](const Section& s) {
    const double c = 2 * micromodulus(m, s, d), s0 = critical_stretch(m, s, d);
    if (s.dim == 3) return pi * c * s0 * s0 * std::pow(d, 5) / 10;
    if (s.dim == 2) return c * s0 * s0 * s.thickness * std::pow(d, 4) / 4;
    return s.area * c * s0 * s0 * std::pow(d, 3) / 6;
  };
  for (const auto& s : {s3, ps, pe, s1}) EXPECT_NEAR(g(s) / m.G0, 1.0, 1e-12) << s.dim;
  EXPECT_NEAR(critical_stretch(m, s3, d), std::sqrt(5 * m.G0 / (6 * m.E * d)), 1e-15);
  EXPECT_NEAR(critical_stretch(m, ps, d), std::sqrt(4 * pi * m.G0 / (9 * m.E * d)), 1e-15);
  EXPECT_NEAR(critical_stretch(m, pe, d), std::sqrt(5 * pi * m.G0 / (12 * m.E * d)), 1e-15);
}

TEST(StableStep, MatchesBruteForceSumOnInteriorParticle) {
  for (int dim : {1, 2, 3}) {
    Section s;
    s.dim = dim;
    s.thickness = 1e-3;
    const int cells = dim == 1 ? 40 : (dim == 2 ? 20 : 12);
    const double dx = 1e-3, delta = 3.015 * dx;
    auto p = test::lattice_store(dim, cells, dx, 3.015, s);
    const Material m{70e9, 2700, 1.0};
    auto a = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear, m, s);
    // Interior particle: own + dual bonds = 2 × Σ_j C β V / |ξ| over the lattice offsets.
    const int r = 4;
    double sum = 0;
    for (int k = -(dim > 2 ? r : 0); k <= (dim > 2 ? r : 0); ++k)
      for (int j = -(dim > 1 ? r : 0); j <= (dim > 1 ? r : 0); ++j)
        for (int i = -r; i <= r; ++i) {
          const double d = dx * std::sqrt(double(i * i + j * j + k * k));
          if (d == 0 || d > delta) continue;
          const double beta = d <= delta - dx / 2 ? 1.0 : (delta + dx / 2 - d) / dx;
          sum += 2 * micromodulus(m, s, delta) * beta * p.volume[0] / d;
        }
    const double expected = std::sqrt(2 * m.rho / sum);
    for (auto& rho : p.density) rho = m.rho;
    // The rows store the pair stiffness in single precision (docs/theory.md §18): 2⁻²⁵ in dt.
    EXPECT_NEAR(critical_time_step(a.bonds, p) / expected, 1.0, 1e-7) << dim;
  }
}

}  // namespace
}  // namespace dhpd
