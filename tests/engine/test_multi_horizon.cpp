// Multi-horizon PD (CMES 2019 §2; docs/theory.md §24) in 1D: α of eq. 7 against its closed form
// at a fine/coarse interface; the uniform-stretch (patch) test it passes at the refined particles
// and misses at the coarse ones; the linear momentum it does not conserve, on jittered two-zone
// clouds where dual horizons conserve it to round-off; the α it cannot define.
#include <gtest/gtest.h>

#include <random>

#include "engine/base/errors.hpp"
#include "engine/physics/ordinary_state.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

constexpr double kFine = 1e-4, kCoarse = 4e-4, kFactor = 3.015;

/// A bar: fine on [0, 24 mm), coarse on [24, 52 mm] (the CMES 2019 bar's left half), positions
/// jittered by `jitter` × their spacing (0: lattices).
ParticleStore two_zone_bar(double jitter, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  ParticleStore p(1);
  std::vector<std::pair<double, double>> points;  // (x, spacing)
  for (int k = 0; k < 240; ++k) points.push_back({(k + 0.5) * kFine, kFine});
  for (int k = 0; k < 70; ++k) points.push_back({0.024 + (k + 0.5) * kCoarse, kCoarse});
  p.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [x, h] = points[i];
    p.reference_position[0][i] = x + jitter * h * unit(rng);
    p.position[0][i] = p.reference_position[0][i];
    p.spacing[i] = h;
    p.horizon[i] = kFactor * h;
    p.volume[i] = h * 1e-6;
    p.density[i] = 8000.0;
    p.id[i] = static_cast<std::int32_t>(i);
  }
  Section s = test::section_of(1);
  set_particle_radii(p, s);
  return p;
}

test::Assembly assemble(const ParticleStore& p, ForceModel model) {
  return test::assemble(p, model, PartialVolume::Linear, Material{200e9, 8000, 1.0},
                        test::section_of(1));
}

// The last fine particle (x = 23.95 mm): coarser cells fill [24, 23.95 + δ_f] of its horizon
// toward +x, and the coarse particles at 24.2, 24.6 and 25.0 mm include it (δ_c = 1.206 mm), so
// α = 2 C_f (δ_f − 0.05 mm) / (3 (C_f + C_c) 0.4 mm) with C ∝ 1/δ²: C_c = C_f / 16.
TEST(MultiHorizon, AlphaOfEquationSevenAtTheInterface) {
  const auto p = two_zone_bar(0.0, 1);
  const auto a = assemble(p, ForceModel::MultiHorizon);
  const std::size_t last_fine = 239;
  const double delta_f = kFactor * kFine;
  const double expected = 2.0 * (delta_f - 0.5 * kFine) / (3.0 * (1.0 + 1.0 / 16.0) * kCoarse);
  EXPECT_NEAR(a.C[last_fine] / a.C[240], 16.0, 1e-9);
  EXPECT_NEAR(a.alpha[2 * last_fine + 1], expected, 1e-12);
  EXPECT_EQ(a.alpha[2 * last_fine], 0.0);  // nothing coarser toward −x
  // A fine particle farther than δ_f from the coarse cells has no coarser material in its
  // horizon: α = 0, though coarse particles include it (their bonds act on it unanswered).
  EXPECT_EQ(a.alpha[2 * 230 + 1], 0.0);
  for (std::size_t i = 240; i < p.size(); ++i) EXPECT_EQ(a.alpha[2 * i] + a.alpha[2 * i + 1], 0.0);
}

/// max |f| over the particles of [from, to) under a uniform stretch ε, in E ε / Δx_coarse.
double stretch_forces(ForceModel model, std::size_t from, std::size_t to) {
  auto p = two_zone_bar(0.0, 1);
  const double eps = 1e-3;
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.displacement[0][i] = eps * p.reference_position[0][i];
    p.position[0][i] = p.reference_position[0][i] + p.displacement[0][i];
  }
  auto a = assemble(p, model);
  internal_force_density(a.bonds, p);
  double largest = 0.0;
  for (std::size_t i = from; i < to; ++i)
    largest = std::max(largest, std::abs(p.force_density[0][i]));
  return largest / (200e9 * eps / kCoarse);
}

// Away from the bar's ends (whose free surfaces pull inward), a uniform stretch puts no force on
// the refined particles (α makes their interaction horizons carry the missing material), but the
// coarse particles near the interface keep 0.22 E ε / Δx: their own states toward the fine side
// are unscaled while the fine particles' states toward them carry α (eq. 3, read as written).
TEST(MultiHorizon, UniformStretchLeavesNoForceOnRefinedParticlesButSomeOnCoarseOnes) {
  const double fine = stretch_forces(ForceModel::MultiHorizon, 20, 240);
  const double coarse = stretch_forces(ForceModel::MultiHorizon, 240, 260);
  const double classical_fine = stretch_forces(ForceModel::ClassicalVariable, 20, 240);
  std::printf(
      "uniform stretch, max |f| / (E ε/Δx_c): multi-horizon fine %.3g, coarse %.3g; "
      "classical-variable fine %.3g\n",
      fine, coarse, classical_fine);
  EXPECT_LT(fine, 1e-6);  // single-precision pair stiffness (docs/theory.md §18)
  EXPECT_GT(coarse, 0.1);
  EXPECT_GT(classical_fine, 1.0);
}

// Linear momentum: |Σ V f| / Σ |V f| under random displacements of jittered two-zone bars.
TEST(MultiHorizon, DoesNotConserveLinearMomentumWhereDualHorizonsDo) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    auto p = two_zone_bar(0.3, seed);
    std::mt19937_64 rng(100 + seed);
    std::uniform_real_distribution<double> unit(-0.5, 0.5);
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.displacement[0][i] = 1e-6 * unit(rng);
      p.position[0][i] = p.reference_position[0][i] + p.displacement[0][i];
    }
    double balance[3];
    int k = 0;
    for (const auto model :
         {ForceModel::DualHorizon, ForceModel::MultiHorizon, ForceModel::ClassicalVariable}) {
      auto q = p;
      auto a = assemble(q, model);
      internal_force_density(a.bonds, q);
      balance[k++] = test::momentum_balance(q).linear;
    }
    std::printf("seed %u: |ΣF|/Σ|F| dual-horizon %.3g, multi-horizon %.3g, classical %.3g\n", seed,
                balance[0], balance[1], balance[2]);
    EXPECT_LT(balance[0], 1e-12);
    EXPECT_GT(balance[1], 1e-6);
    EXPECT_GT(balance[2], 1e-4);
  }
}

/// The ordinary state-based forces of `p` (1D, E = 200 GPa, constant ω, linear partial volumes,
/// no surface factors) under `model`; returns α of the interaction horizons.
std::vector<double> state_forces(ParticleStore& p, ForceModel model) {
  const auto rows = build_bond_rows(p, PartialVolume::Linear, {});
  const std::vector<Material> materials{{200e9, 8000.0, 0.0, std::nan("")}};
  OrdinaryState state(
      rows, p,
      {test::section_of(1), model, PartialVolume::Linear, Influence::Constant, &materials, false});
  state.forces(rows, p);
  return state.interaction_scale();
}

// The state-based form (§24): m_i and θ_i over the horizon a refined body would give i (its
// lattice continued into the coarser cells), α from eq. 7 with the linear solid's integrand: a
// uniform stretch leaves no force on the refined particles, 0.35 E ε / Δx_c on coarse ones.
TEST(MultiHorizon, StateBasedUniformStretchLeavesNoForceOnRefinedParticles) {
  auto p = two_zone_bar(0.0, 1);
  const double eps = 1e-3;
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.displacement[0][i] = eps * p.reference_position[0][i];
    p.position[0][i] = p.reference_position[0][i] + p.displacement[0][i];
  }
  const auto alpha = state_forces(p, ForceModel::MultiHorizon);
  double fine = 0.0, coarse = 0.0;
  for (std::size_t i = 20; i < 240; ++i) fine = std::max(fine, std::abs(p.force_density[0][i]));
  for (std::size_t i = 240; i < 260; ++i)
    coarse = std::max(coarse, std::abs(p.force_density[0][i]));
  const double scale = 200e9 * eps / kCoarse;
  std::printf(
      "state-based multi-horizon, uniform stretch: fine %.3g, coarse %.3g E ε/Δx_c; α at "
      "the interface %.4f\n",
      fine / scale, coarse / scale, alpha[2 * 239 + 1]);
  EXPECT_LT(fine, 1e-8 * scale);
  EXPECT_GT(coarse, 0.1 * scale);
  EXPECT_GT(alpha[2 * 239 + 1], 0.0);
  EXPECT_EQ(alpha[2 * 230 + 1], 0.0);
}

TEST(MultiHorizon, StateBasedDoesNotConserveLinearMomentum) {
  auto p = two_zone_bar(0.3, 4);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.displacement[0][i] = 1e-6 * unit(rng);
    p.position[0][i] = p.reference_position[0][i] + p.displacement[0][i];
  }
  auto q = p;
  state_forces(p, ForceModel::MultiHorizon);
  state_forces(q, ForceModel::DualHorizon);
  const double multi = test::momentum_balance(p).linear, dual = test::momentum_balance(q).linear;
  std::printf("state-based |ΣF|/Σ|F|: multi-horizon %.3g, dual-horizon %.3g\n", multi, dual);
  EXPECT_LT(dual, 1e-12);
  EXPECT_GT(multi, 1e-6);
}

// Coarser material in a particle's horizon that does not include it: eq. 7 has no interaction
// horizon to put the missing integrand on: spacings 1.1× apart, 3.4 mm between the particles, so
// j's cell reaches into i's horizon (linear partial volume: i owns a bond on j) while
// δ_j = 3.3 mm < 3.4 mm.
TEST(MultiHorizon, AnEmptyInteractionHorizonLeavesAlphaUndefined) {
  ParticleStore p(1);
  p.resize(2);
  const double h[2] = {1.0e-3, 1.1e-3};
  const double x[2] = {0.0, 3.4e-3};
  for (std::size_t i = 0; i < 2; ++i) {
    p.reference_position[0][i] = p.position[0][i] = x[i];
    p.spacing[i] = h[i];
    p.horizon[i] = 3.0 * h[i];
    p.volume[i] = h[i] * 1e-6;
    p.density[i] = 8000.0;
  }
  set_particle_radii(p, test::section_of(1));
  try {
    assemble(p, ForceModel::MultiHorizon);
    ADD_FAILURE() << "α was defined";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is undefined"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dhpd
