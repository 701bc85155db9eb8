// Shared by the level-interface tests (docs/theory.md §14): a homogeneous strain imposed on every
// particle and the largest force it leaves inside a body and near its faces.
#pragma once
#include <algorithm>
#include <cmath>

#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "tests/support/engine.hpp"

namespace dhpd::test {

/// u = ε X for every particle (ε symmetric, its first dim axes).
inline void apply_strain(ParticleStore& p, const double eps[3][3]) {
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int a = 0; a < p.dim(); ++a) {
      double u = 0.0;
      for (int b = 0; b < p.dim(); ++b) u += eps[a][b] * p.reference_position[b][i];
      test::set_displacement(p, a, i, u);
    }
}
inline void apply_strain(Simulation& sim, const double eps[3][3]) {
  apply_strain(sim.particles(), eps);
}

struct Forces {
  double inside = 0.0, edge = 0.0;  ///< largest |f| away from the faces (> `margin`) and near them
};

inline Forces forces_under(Simulation& sim, const double eps[3][3], double margin, double size) {
  apply_strain(sim, eps);
  auto& p = sim.particles();
  internal_force_density(sim.bonds(), p);
  Forces f;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double f2 = 0.0;
    bool inside = true;
    for (int a = 0; a < p.dim(); ++a) {
      f2 += p.force_density[a][i] * p.force_density[a][i];
      const double x = p.reference_position[a][i];
      inside = inside && x > margin && x < size - margin;
    }
    (inside ? f.inside : f.edge) = std::max(inside ? f.inside : f.edge, std::sqrt(f2));
  }
  return f;
}

inline constexpr double kShear[3][3] = {
    {1e-3, 3e-4, -2e-4}, {3e-4, -5e-4, 1e-4}, {-2e-4, 1e-4, 4e-4}};

}  // namespace dhpd::test
