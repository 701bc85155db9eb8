// Ordinary state-based DH-PD (docs/theory.md §20): patch tests (θ = tr ε, the continuum energy,
// no force inside a uniformly strained body), momentum with horizons varying 10×, the gather
// against a brute-force scatter of IJNME 2016 eq. 42, and forces as the gradient of the energy.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "engine/physics/ordinary_state.hpp"
#include "tests/support/engine.hpp"
#include "tests/support/interfaces.hpp"

namespace dhpd {
namespace {

struct StateAssembly {
  BondRows bonds;
  std::vector<Material> materials;
  OrdinaryState model;
};

StateAssembly assemble_state(const ParticleStore& p, const Section& s, double nu,
                             ForceModel horizon = ForceModel::DualHorizon,
                             Influence w = Influence::Constant,
                             PartialVolume rule = PartialVolume::Linear, bool surface = false) {
  StateAssembly a;
  a.bonds = build_bond_rows(p, rule, {});
  a.materials = {{2e9, 1000.0, 0.0, s.dim == 1 ? std::nan("") : nu}};
  a.model = OrdinaryState(a.bonds, p, {s, horizon, rule, w, &a.materials, surface});
  return a;
}

using test::section_of;

/// Whether particle i lies at least `margin` inside the lattice [0, L]^dim.
bool interior(const ParticleStore& p, std::size_t i, double L, double margin) {
  for (int a = 0; a < p.dim(); ++a)
    if (p.reference_position[a][i] < margin || p.reference_position[a][i] > L - margin)
      return false;
  return true;
}

/// The continuum energy density κ (tr ε)²/2 + G ε^d : ε^d of the dimension (ε^d = ε − tr ε I/n).
double continuum_energy(const double eps[3][3], int n, StateModuli m) {
  double tr = 0.0;
  for (int a = 0; a < n; ++a) tr += eps[a][a];
  double dd = 0.0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const double d = eps[a][b] - (a == b ? tr / n : 0.0);
      dd += d * d;
    }
  return 0.5 * m.bulk * tr * tr + m.shear * dd;
}

struct PatchCase {
  int dim;
  PlaneMode plane;
  double nu;
};

class UniformStrain : public ::testing::TestWithParam<PatchCase> {};

// Inside a body under uniform strain: θ is the trace, W the continuum value (to the lattice's
// anisotropy of the fourth moment under shear), and the force vanishes.
TEST_P(UniformStrain, DilatationIsTheTraceEnergyTheContinuumsForceZero) {
  const auto c = GetParam();
  const auto s = section_of(c.dim, c.plane);
  const int cells = c.dim == 1 ? 40 : (c.dim == 2 ? 24 : 16);
  const double dx = 1e-3, L = cells * dx, delta = 3.015 * dx;
  auto p = test::lattice_store(c.dim, cells, dx, 3.015, s);
  auto a = assemble_state(p, s, c.nu);
  const auto moduli = state_moduli(a.materials[0], s);
  const double e0 = 1e-6;
  const double dilation[3][3] = {{e0, 0, 0}, {0, e0, 0}, {0, 0, e0}};
  const double general[3][3] = {
      {e0, 0.7 * e0, -0.4 * e0}, {0.7 * e0, -0.5 * e0, 0.3 * e0}, {-0.4 * e0, 0.3 * e0, 0.8 * e0}};
  double worst_theta = 0, worst_dilation_energy = 0, worst_general_energy = 0, force = 0, scale = 0;
  for (const auto* eps : {dilation, general}) {
    test::apply_strain(p, eps);
    a.model.forces(a.bonds, p);
    double tr = 0.0;
    for (int d = 0; d < c.dim; ++d) tr += eps[d][d];
    const double w_cont = continuum_energy(eps, c.dim, moduli);
    // θ and W need a full horizon; the force also full horizons of the neighbours (their θ).
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (interior(p, i, L, 2 * delta + dx))
        for (int d = 0; d < c.dim; ++d) force = std::max(force, std::abs(p.force_density[d][i]));
      if (!interior(p, i, L, delta + dx)) continue;
      worst_theta = std::max(worst_theta, std::abs(a.model.dilatation()[i] - tr) / std::abs(tr));
    }
    // The energy of an interior particle: the model's per-particle W (θ and e^d of its row).
    const auto w = a.model.energy_density(a.bonds, p);
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!interior(p, i, L, delta + dx)) continue;
      const double err = std::abs(w[i] - w_cont) / w_cont;
      (eps == dilation ? worst_dilation_energy : worst_general_energy) =
          std::max(eps == dilation ? worst_dilation_energy : worst_general_energy, err);
    }
    // Force scale: one bond's force density at this strain.
    scale = std::max(scale, moduli.bulk * e0 / dx);
  }
  std::printf(
      "%dD nu %.2f: |θ − tr ε|/tr ε ≤ %.2e, W dilatation ≤ %.2e, general ≤ %.2e, "
      "|f| ≤ %.2e of κ ε/Δx\n",
      c.dim, c.nu, worst_theta, worst_dilation_energy, worst_general_energy, force / scale);
  EXPECT_LT(worst_theta, 1e-5);
  EXPECT_LT(worst_dilation_energy, 1e-5);
  EXPECT_LT(worst_general_energy, c.dim == 1 ? 1e-5 : 0.05);
  EXPECT_LT(force, 1e-8 * scale);
}

INSTANTIATE_TEST_SUITE_P(Dimensions, UniformStrain,
                         ::testing::Values(PatchCase{1, PlaneMode::Strain, 0.0},
                                           PatchCase{2, PlaneMode::Stress, 0.0},
                                           PatchCase{2, PlaneMode::Stress, 0.3},
                                           PatchCase{2, PlaneMode::Strain, 0.35},
                                           PatchCase{3, PlaneMode::Strain, 0.3}));

// Near the free edges of a uniformly strained plate or block: θ and W against the continuum's,
// the mean over the particles within δ of an edge, with and without the surface correction.
TEST(SurfaceCorrection, BringsEdgeParticlesTowardsTheContinuum) {
  for (const int dim : {2, 3}) {
    const auto s = section_of(dim, PlaneMode::Stress);
    const int cells = dim == 2 ? 24 : 12;
    const double dx = 1e-3, L = cells * dx, delta = 3.015 * dx, e0 = 1e-6;
    const double uniaxial[3][3] = {{e0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    const double other[3][3] = {{0, 0, 0}, {0, e0, 0}, {0, 0, 0}};
    const double shear[3][3] = {{0, e0, 0}, {e0, 0, 0}, {0, 0, 0}};
    double mean[2][2] = {};  // [corrected][θ, W]
    int count = 0;
    for (const bool surface : {false, true}) {
      auto p = test::lattice_store(dim, cells, dx, 3.015, s);
      auto a = assemble_state(p, s, 0.3, ForceModel::DualHorizon, Influence::Constant,
                              PartialVolume::Linear, surface);
      const auto moduli = state_moduli(a.materials[0], s);
      count = 0;
      for (const auto* eps : {uniaxial, other, shear}) {
        test::apply_strain(p, eps);
        const auto w = a.model.energy_density(a.bonds, p);
        double tr = 0.0;
        for (int d = 0; d < dim; ++d) tr += eps[d][d];
        const double w_cont = continuum_energy(eps, dim, moduli);
        for (std::size_t i = 0; i < p.size(); ++i) {
          if (interior(p, i, L, delta)) continue;  // the edge layer only
          if (tr != 0.0) mean[surface][0] += std::abs(a.model.dilatation()[i] - tr) / std::abs(tr);
          mean[surface][1] += std::abs(w[i] - w_cont) / w_cont;
          ++count;
        }
      }
      mean[surface][0] /= count * 2.0 / 3.0;  // two of the three strains have a trace
      mean[surface][1] /= count;
    }
    std::printf(
        "%dD edge layer, mean |θ − tr ε|/tr ε: %.3f without, %.3f with the correction; "
        "mean |W − W_c|/W_c: %.3f without, %.3f with\n",
        dim, mean[0][0], mean[1][0], mean[0][1], mean[1][1]);
    // Measured: θ 0.117 → 4e-7 (2D), 0.100 → 0.005 (3D: edge and corner particles whose exact
    // tensor is not positive along every bond keep the axes' ellipse); W 0.130 → 0.050, 0.135 →
    // 0.069. With the ellipse alone θ was 0.057 / 0.062 and W 0.099 / 0.115.
    EXPECT_LT(mean[1][0], 0.1 * mean[0][0]);
    EXPECT_LT(mean[1][1], 0.6 * mean[0][1]);
  }
}

// A graded body: a 0.5 mm zone inside a 1 mm plate, away from the free edges. Without the
// correction an isotropic expansion gives θ = tr ε and W the continuum's everywhere, at the level
// interface too (each m_i is its particle's own sum), but a general strain does not there: a fine
// particle's horizon holds only a few coarse neighbours, so its second moments are far from
// isotropic. The correction's exact dilatation (theory.md §20.5) gives the trace of every uniform
// strain there. The force the strain leaves at the interface (dual sums asymmetric) is measured.
TEST(GradedLattice, DilatationIsTheTraceAcrossTheInterfaceWithTheCorrection) {
  const auto s = section_of(2, PlaneMode::Stress);
  const double L = 0.04, inner = 0.0005, outer = 0.001, delta = 3.015 * outer;
  const auto pts =
      geometry::fill_lattice({{geometry::Box{{0, 0, 0}, {L, L, 0}}, outer, 0},
                              {geometry::Box{{0.015, 0.015, 0}, {0.025, 0.025, 0}}, inner, 0}},
                             2);
  const double e0 = 1e-6;
  const double isotropic[3][3] = {{e0, 0, 0}, {0, e0, 0}, {0, 0, 0}};
  const double general[3][3] = {{e0, 0.4 * e0, 0}, {0.4 * e0, -0.3 * e0, 0}, {0, 0, 0}};
  for (const bool corrected : {false, true}) {
    auto p = test::store_from_points(pts, 2, 3.015, s);
    auto a = assemble_state(p, s, 0.3, ForceModel::DualHorizon, Influence::Constant,
                            PartialVolume::Linear, corrected);
    const auto moduli = state_moduli(a.materials[0], s);
    double worst[2] = {0, 0}, worst_energy[2] = {0, 0}, interface_force = 0.0, edge_force = 0.0;
    for (int c = 0; c < 2; ++c) {
      const auto& eps = c == 0 ? isotropic : general;
      test::apply_strain(p, eps);
      a.model.forces(a.bonds, p);
      const double tr = eps[0][0] + eps[1][1];
      const double w_cont = continuum_energy(eps, 2, moduli);
      const auto w = a.model.energy_density(a.bonds, p);
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double y = p.reference_position[1][i];
        const double f = std::hypot(p.force_density[0][i], p.force_density[1][i]);
        if (!interior(p, i, L, delta + outer)) {
          if (c == 1 && std::abs(y - 0.5 * L) < 0.005) edge_force = std::max(edge_force, f);
          continue;
        }
        worst[c] = std::max(worst[c], std::abs(a.model.dilatation()[i] - tr) / std::abs(tr));
        worst_energy[c] = std::max(worst_energy[c], std::abs(w[i] - w_cont) / w_cont);
        if (c == 1) interface_force = std::max(interface_force, f);
      }
    }
    std::printf(
        "graded plate, correction %s: |θ − tr ε|/tr ε ≤ %.2e (isotropic), %.2e (general "
        "strain); |W − W_c|/W_c ≤ %.2e (isotropic), %.3f (general); largest force inside %.3f "
        "of the free edge's\n",
        corrected ? "on" : "off", worst[0], worst[1], worst_energy[0], worst_energy[1],
        interface_force / edge_force);
    EXPECT_LT(worst[0], 1e-5);
    EXPECT_LT(worst_energy[0], 1e-5);  // W = κθ²/2 with no deviatoric part: exact where θ is
    if (corrected)
      EXPECT_LT(worst[1], 1e-5);  // the trace of every uniform strain
    else
      EXPECT_GT(worst[1], 0.1);  // measured 0.37: the anisotropic second moments
  }
}

class StateMomentum : public ::testing::TestWithParam<int> {};

// Horizons varying 10× on a random cloud: the dual-horizon state-based forces balance to round-off;
// the classical variable-horizon variant (j's state on i's bond) puts ghost forces there.
TEST_P(StateMomentum, DualHorizonBalancesAndClassicalVariableDoesNot) {
  const int dim = GetParam();
  const std::size_t n = dim == 1 ? 300 : (dim == 2 ? 600 : 700);
  const double h = dim == 1 ? 2e-3 : (dim == 2 ? 0.01 : 0.03);
  const auto s = section_of(dim);
  for (const auto rule : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact})
    for (const auto w : {Influence::Constant, Influence::InverseDistance}) {
      auto p = test::random_cloud(dim, n, h, 10.0, 3.015, 11 + dim);
      auto q = p;
      // With the surface correction: its factors are the owner's, the same in both rows.
      auto dh = assemble_state(p, s, 0.3, ForceModel::DualHorizon, w, rule, true);
      auto cv = assemble_state(q, s, 0.3, ForceModel::ClassicalVariable, w, rule);
      dh.model.forces(dh.bonds, p);
      cv.model.forces(cv.bonds, q);
      const auto a = test::momentum_balance(p), b = test::momentum_balance(q);
      std::printf("%dD %s %s: DH |ΣF|/Σ|F| = %.2e, |ΣM|/Σ|M| = %.2e; classical variable %.2e\n",
                  dim, std::string(to_string(rule)).c_str(), std::string(to_string(w)).c_str(),
                  a.linear, a.angular, b.linear);
      EXPECT_LT(a.linear, 1e-12);
      EXPECT_LT(a.angular, 1e-12);
      EXPECT_GT(b.linear, 1e6 * std::max(a.linear, 1e-18));
    }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, StateMomentum, ::testing::Values(1, 2, 3));

}  // namespace
}  // namespace dhpd
