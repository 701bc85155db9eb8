// Fracture of the ordinary state-based family (docs/theory.md §20.4): the factor Φ of the critical
// stretch against the energy a lattice releases when its bonds across a plane break, and a run
// that breaks bonds with momentum exact, bit-exact restarts and 1 = 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/checkpoint/checkpoint.hpp"
#include "engine/physics/ordinary_state.hpp"
#include "tests/support/checkpoint.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

// Every bond at stretch s (an isotropic expansion): the shares ½ t e V_i V_j of the bonds that
// cross the plane x = L/2, per unit area, are s² δ Φ up to the lattice's quadrature.
TEST(StateFracture, FactorIsTheEnergyTheCrossingBondsHold) {
  for (const int dim : {1, 2, 3})
    for (const auto w : {Influence::Constant, Influence::InverseDistance}) {
      Section s;
      s.dim = dim;
      s.plane = PlaneMode::Stress;
      s.thickness = 1.0;
      s.area = 1.0;
      const int cells = dim == 1 ? 60 : (dim == 2 ? 40 : 16);
      const double dx = 1e-3, L = cells * dx, delta = 3.015 * dx, stretch = 1e-4;
      auto p = test::lattice_store(dim, cells, dx, 3.015, s);
      for (std::size_t i = 0; i < p.size(); ++i)
        for (int a = 0; a < dim; ++a)
          test::set_displacement(p, a, i, stretch * (p.reference_position[a][i] - 0.5 * L));
      const std::vector<Material> mats{{2e9, 1000.0, 1.0, dim == 1 ? std::nan("") : 0.25}};
      const auto rows = build_bond_rows(p, PartialVolume::Linear, {});
      OrdinaryState model(rows, p,
                          {s, ForceModel::DualHorizon, PartialVolume::Linear, w, &mats, false});
      model.forces(rows, p);  // θ of the stretched state
      const auto moduli = state_moduli(mats[0], s);
      const int n = dim;
      double held = 0.0;
      for (std::size_t i = 0; i < p.size(); ++i)
        for (auto k = rows.begin(i); k < rows.end(i); ++k) {
          const auto j = static_cast<std::size_t>(rows.other[k]);
          if (!rows.has_own(k) ||
              (p.reference_position[0][i] < 0.5 * L) == (p.reference_position[0][j] < 0.5 * L))
            continue;
          // t_ij of eq. 20.3 from the model's own m_i and θ_i; e = s |ξ|.
          const double xi = rows.length(k), e = stretch * xi;
          const double m = model.weighted_volume()[i], theta = model.dilatation()[i];
          const double omega = w == Influence::Constant ? 1.0 : p.horizon[i] / xi;
          const double t = omega * (n * moduli.bulk * theta / m * xi +
                                    n * (n + 2) * moduli.shear / m * (e - theta * xi / n));
          held += 0.5 * t * e * bond_weight(p, PartialVolume::Linear, i, j, xi) * p.volume[j] *
                  p.volume[i];
        }
      const double area = dim == 1 ? 1.0 : std::pow(L, dim - 1);
      const double measured = held / area / (stretch * stretch * delta);
      const double phi = state_fracture_factor(mats[0], s, w);
      std::printf("%dD %s: held / (s² δ) = %.4g, Φ = %.4g (ratio %.3f)\n", dim,
                  std::string(to_string(w)).c_str(), measured, phi, measured / phi);
      EXPECT_NEAR(measured / phi, 1.0, 0.06);
    }
}

// With ω = δ/|ξ| at bond-based PD's own Poisson's ratio the critical stretch is eq. 36's.
TEST(StateFracture, CriticalStretchIsBondBasedsAtItsPoissonsRatio) {
  for (const int dim : {1, 2, 3}) {
    Section s;
    s.dim = dim;
    s.plane = PlaneMode::Stress;
    s.thickness = 1.0;
    s.area = 1.0;
    const Material m{72e9, 2440, 3.8, dim == 1 ? std::nan("") : implied_poisson_ratio(s)};
    const double delta = 3e-3;
    const double state =
        std::sqrt(m.G0 / (state_fracture_factor(m, s, Influence::InverseDistance) * delta));
    const double bond = critical_stretch(m, s, delta);
    std::printf("%dD: s0 state-based %.6e, bond-based %.6e\n", dim, state, bond);
    EXPECT_NEAR(state / bond, 1.0, 1e-4);
  }
}

/// A 2D plate, its halves moving apart (momentum zero), a notch between them: bonds break.
SimulationSetup parting_plate(double nu) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.family = ModelFamily::OrdinaryState;
  s.interface_correction = false;
  s.materials = {{72e9, 2440, 3.8, nu}};
  s.partial_volume = PartialVolume::Linear;
  s.effects.fracture = true;
  s.points = geometry::fill_lattice({{test::Box{{0, 0, 0}, {0.02, 0.02, 0}}, 5e-4, 0},
                                     {test::Box{{0.02, 0, 0}, {0.03, 0.02, 0}}, 1e-3, 0}},
                                    2);
  s.cracks = {{{{0.0, 0.01, 0}, {0.008, 0.01, 0}}}};
  for (const double sign : {1.0, -1.0}) {
    InitialCondition ic;
    ic.region = test::Box{{0, sign > 0 ? 0.01 : 0.0, 0}, {0.03, sign > 0 ? 0.02 : 0.01, 0}};
    ic.velocity = Vec3{0, 6.0 * sign, 0};
    s.initial_conditions.push_back(ic);
  }
  return s;
}

TEST(StateFracture, BondsBreakWithMomentumExactRestartsAndThreads) {
  const auto s = parting_plate(0.3);
  Simulation whole(s);
  double scale = 0.0;
  {
    const auto& p = whole.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      scale += p.density[i] * p.volume[i] * std::hypot(p.velocity[0][i], p.velocity[1][i]);
  }
  whole.run_steps(300);
  const auto e = whole.energies();
  const double drift = std::hypot(e.momentum[0], e.momentum[1]) / scale;
  std::printf("broken %lld, |P| / Σ|p| = %.2e\n", static_cast<long long>(whole.broken_bonds()),
              drift);
  EXPECT_GT(whole.broken_bonds(), 100);
  EXPECT_LT(drift, 1e-12);
  test::expect_restart_and_one_thread_exact(s, whole, 150, 150);
}

}  // namespace
}  // namespace dhpd
