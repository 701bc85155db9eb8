// Exact partial volumes in the engine (CMAME 2017 App. A; docs/theory.md §7): lattice quadrature,
// interior energy density, the bonds they create and momentum balance on varying horizons.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "geometry/intersection.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

using geometry::partial_volume_fraction;

Section section_of(int dim, PlaneMode plane = PlaneMode::Stress) {
  Section s;
  s.dim = dim;
  s.plane = plane;
  s.thickness = 2e-3;
  s.area = 3e-4;
  return s;
}

std::size_t centre_of(const ParticleStore& p, int dim, double middle) {
  std::size_t centre = 0;
  double best = 1e300;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d = 0;
    for (int a = 0; a < dim; ++a) d += std::pow(p.reference_position[a][i] - middle, 2);
    if (d < best) best = d, centre = i;
  }
  return centre;
}

struct Interior {
  double quadrature, energy_ratio;
};

/// Quadrature and W_i / W_continuum of the centre particle of a lattice under isotropic strain.
Interior interior_of(int dim, PlaneMode plane, PartialVolume pv) {
  const Section s = section_of(dim, plane);
  const int cells = dim == 2 ? 21 : 13;
  const double dx = 1e-3, eps = 1e-4, E = 70e9;
  auto p = test::lattice_store(dim, cells, dx, 3.015, s);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < dim; ++a) test::set_displacement(p, a, i, eps * p.reference_position[a][i]);
  const Material m{E, 2400, 1.0};
  const auto a = test::assemble(p, ForceModel::DualHorizon, pv, m, s);
  std::vector<double> q, w;
  horizon_quadrature(a.bonds, p, pv, s, q);
  strain_energy_density(a.bonds, a.constants(p), w);
  const double continuum =
      dim == 3 ? 3.0 * E * eps * eps : (plane == PlaneMode::Stress ? 1.5 : 1.6) * E * eps * eps;
  const auto c = centre_of(p, dim, cells * dx / 2);
  return {q[c], w[c] / continuum};
}

TEST(Quadrature, ExactIsWithinOnePointFivePercentAndBeatsNoneAndLinear) {
  for (int dim : {2, 3}) {
    const auto none = interior_of(dim, PlaneMode::Stress, PartialVolume::None);
    const auto linear = interior_of(dim, PlaneMode::Stress, PartialVolume::Linear);
    const auto exact = interior_of(dim, PlaneMode::Stress, PartialVolume::Exact);
    std::printf(
        "%dD interior quadrature (V_i + sum beta V_j)/|ball|: none %.4f, linear %.4f, "
        "exact %.4f\n",
        dim, none.quadrature, linear.quadrature, exact.quadrature);
    EXPECT_NEAR(exact.quadrature, 1.0, 0.015) << dim;
    EXPECT_LT(std::abs(exact.quadrature - 1), std::abs(none.quadrature - 1)) << dim;
    EXPECT_LT(std::abs(exact.quadrature - 1), std::abs(linear.quadrature - 1)) << dim;
  }
}

TEST(ExactPartialVolume, InteriorEnergyDensityWithinOnePointFivePercentOfContinuum) {
  const std::vector<std::pair<int, PlaneMode>> sections{
      {2, PlaneMode::Stress}, {2, PlaneMode::Strain}, {3, PlaneMode::Stress}};
  for (const auto& [dim, plane] : sections) {
    const auto none = interior_of(dim, plane, PartialVolume::None);
    const auto linear = interior_of(dim, plane, PartialVolume::Linear);
    const auto exact = interior_of(dim, plane, PartialVolume::Exact);
    std::printf("%dD %s W/W_continuum: none %.4f, linear %.4f, exact %.4f\n", dim,
                plane == PlaneMode::Stress ? "stress" : "strain", none.energy_ratio,
                linear.energy_ratio, exact.energy_ratio);
    EXPECT_NEAR(exact.energy_ratio, 1.0, 0.015) << dim;
  }
}

/// Every pair with β > 0 is a bond, including pairs beyond δ_i (up to δ_i + r_j), with the
/// fraction of the geometry module as its weight.
TEST(ExactPartialVolume, BondsAreExactlyThePairsWithPositiveFraction) {
  for (int dim : {1, 2, 3}) {
    const auto p =
        test::random_cloud(dim, dim == 1 ? 80 : 250, dim == 3 ? 0.06 : 0.02, 4.0, 3.015, 9 + dim);
    const auto bonds = build_bond_rows(p, PartialVolume::Exact, {});
    std::size_t expected = 0, beyond = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      for (std::size_t j = 0; j < p.size(); ++j) {
        if (i == j) continue;
        double d2 = 0;
        for (int a = 0; a < dim; ++a)
          d2 += std::pow(p.reference_position[a][j] - p.reference_position[a][i], 2);
        const double d = std::sqrt(d2);
        if (partial_volume_fraction(dim, d, p.horizon[i], p.radius[j]) > 0) ++expected;
        if (partial_volume_fraction(dim, d, p.horizon[i], p.radius[j]) > 0 && d > p.horizon[i])
          ++beyond;
      }
    EXPECT_EQ(bonds.bond_count(), expected) << dim;
    EXPECT_GT(beyond, 0u) << dim;
    for (std::size_t i = 0; i < p.size(); ++i)
      for_each_own_bond(bonds, i, [&](std::int64_t k, std::size_t j) {
        ASSERT_EQ(bond_weight(p, PartialVolume::Exact, i, j, bonds.length(k)),
                  partial_volume_fraction(dim, bonds.length(k), p.horizon[i], p.radius[j]));
      });
  }
}

TEST(ExactPartialVolume, MomentumBalancesOnVaryingHorizons) {
  for (int dim : {1, 2, 3}) {
    const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 600 : 700);
    const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.01 : 0.03);
    auto p = test::random_cloud(dim, n, h, 10.0, 3.015, 42 + dim);
    Section s;
    s.dim = dim;
    const auto a = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Exact,
                                  Material{1e9, 1000, 1.0}, s);
    internal_force_density(a.bonds, p);
    double F[3] = {0, 0, 0}, M[3] = {0, 0, 0}, scale_f = 0, scale_m = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      double f[3], y[3];
      for (int k = 0; k < 3; ++k)
        f[k] = p.force_density[k][i] * p.volume[i], y[k] = p.position[k][i];
      const double fn = std::hypot(f[0], f[1], f[2]);
      const double m[3] = {y[1] * f[2] - y[2] * f[1], y[2] * f[0] - y[0] * f[2],
                           y[0] * f[1] - y[1] * f[0]};
      for (int k = 0; k < 3; ++k) F[k] += f[k], M[k] += m[k];
      scale_f += fn, scale_m += fn * std::hypot(y[0], y[1], y[2]);
    }
    const double lin = std::hypot(F[0], F[1], F[2]) / scale_f;
    const double ang = std::hypot(M[0], M[1], M[2]) / scale_m;
    std::printf("%dD exact: |sum F|/sum|F| = %.3e, |sum M|/sum|M| = %.3e\n", dim, lin, ang);
    EXPECT_GT(scale_f, 0.0);
    EXPECT_LT(lin, 1e-12) << dim;
    EXPECT_LT(ang, 1e-12) << dim;
  }
}

}  // namespace
}  // namespace dhpd

namespace dhpd {
namespace {

// δ = 3Δx exactly, as the papers write it: the neighbours at distance δ (up to round-off) are
// inside, with β = ½ (linear) or 1 (none). Before the tie tolerance a 1D bar lost that shell.
TEST(HorizonTie, NeighboursAtExactlyTheHorizonAreBonded) {
  for (const int dim : {1, 2, 3})
    for (const auto rule : {PartialVolume::None, PartialVolume::Linear}) {
      Section s;
      s.dim = dim;
      const int cells = dim == 3 ? 9 : 13;
      const auto p = test::lattice_store(dim, cells, 1e-3, 3.0, s);
      const auto rows = build_bond_rows(p, rule, {});
      // Lattice points with |k|² ≤ 9 around the centre particle, less itself.
      int expected = 0;
      for (int a = -3; a <= 3; ++a)
        for (int b = dim > 1 ? -3 : 0; b <= (dim > 1 ? 3 : 0); ++b)
          for (int c = dim > 2 ? -3 : 0; c <= (dim > 2 ? 3 : 0); ++c)
            expected += (a * a + b * b + c * c <= 9 && (a || b || c)) ? 1 : 0;
      std::size_t centre = 0;
      double best = HUGE_VAL;
      for (std::size_t i = 0; i < p.size(); ++i) {
        double d = 0;
        for (int a = 0; a < dim; ++a)
          d += std::pow(p.reference_position[a][i] - 0.5 * cells * 1e-3, 2);
        if (d < best) best = d, centre = i;
      }
      EXPECT_EQ(rows.own_count(centre), expected) << dim << "D " << to_string(rule);
    }
}

}  // namespace
}  // namespace dhpd
