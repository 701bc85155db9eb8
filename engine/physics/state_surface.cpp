// Surface correction of the ordinary state-based family (docs/theory.md §20.5; the factors of
// Madenci & Oterkus, Peridynamic Theory and Its Applications (2014) §4.2, for this model's terms).
#include <array>
#include <cmath>

#include "engine/base/parallel.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd {

SurfaceFactors surface_factors(const BondRows& rows, const ParticleStore& p,
                               const OrdinaryStateInputs& in, const std::vector<double>& m,
                               const std::vector<double>& own_weight) {
  const int n = in.section.dim;
  const std::size_t count = p.size();
  using Axes = std::array<double, 3>;
  std::vector<Axes> dil(count, Axes{1, 1, 1}), dev(count, Axes{1, 1, 1});
  const auto unit = [&](std::size_t i, std::size_t j, double length, int a) {
    return (p.reference_position[a][j] - p.reference_position[a][i]) / length;
  };
  const auto N = static_cast<std::int64_t>(count);
  // Per particle and axis a, a uniaxial strain ε along a: the continuum's θ = ε and deviatoric
  // energy G ε² (1 − 1/n) over the particle's own (θ = ε (n/m) Σ w |ξ|² n_a²; e^d = ε |ξ| (n_a² −
  // 1/n) with θ at its continuum value).
#pragma omp parallel for schedule(static) if (N >= kParallelMinParticles)
  for (std::int64_t s = 0; s < N; ++s) {
    const auto i = static_cast<std::size_t>(s);
    if (!(m[i] > 0.0)) continue;
    const auto moduli =
        state_moduli((*in.materials)[static_cast<std::size_t>(p.material[i])], in.section);
    const double Q = n * (n + 2.0) * moduli.shear / m[i];
    for (int a = 0; a < n; ++a) {
      double second = 0.0, deviatoric = 0.0;
      for (auto k = rows.begin(i); k < rows.end(i); ++k) {
        if (!rows.has_own(k)) continue;
        const double length = rows.length(k);
        const double na = unit(i, static_cast<std::size_t>(rows.other[k]), length, a);
        const double w = own_weight[k] * length * length;
        second += w * na * na;
        deviatoric += w * (na * na - 1.0 / n) * (na * na - 1.0 / n);
      }
      const double theta = n * second / m[i];
      if (theta > 0.0) dil[i][a] = 1.0 / theta;
      if (n > 1 && deviatoric > 0.0)
        dev[i][a] = moduli.shear * (1.0 - 1.0 / n) / (0.5 * Q * deviatoric);
    }
  }
  // Per entry: the owner's factors read along the bond as an ellipse (ellipsoid): i's for its own
  // bond, j's for the bond j owns on i (the reaction of j's state, which row j computes the same).
  SurfaceFactors out;
  for (auto* v :
       {&out.own_dilatation, &out.own_deviatoric, &out.dual_dilatation, &out.dual_deviatoric})
    v->assign(rows.flags.size(), 1.0);
  const auto along = [&](const Axes& f, const double* na) {
    double sum = 0.0;
    for (int a = 0; a < n; ++a) sum += (na[a] / f[a]) * (na[a] / f[a]);
    return 1.0 / std::sqrt(sum);
  };
#pragma omp parallel for schedule(static) if (N >= kParallelMinParticles)
  for (std::int64_t s = 0; s < N; ++s) {
    const auto i = static_cast<std::size_t>(s);
    for (auto k = rows.begin(i); k < rows.end(i); ++k) {
      const auto j = static_cast<std::size_t>(rows.other[k]);
      const double length = rows.length(k);
      double na[3] = {0, 0, 0};
      for (int a = 0; a < n; ++a) na[a] = unit(i, j, length, a);
      out.own_dilatation[k] = along(dil[i], na);
      out.own_deviatoric[k] = along(dev[i], na);
      out.dual_dilatation[k] = along(dil[j], na);
      out.dual_deviatoric[k] = along(dev[j], na);
    }
  }
  return out;
}

}  // namespace dhpd
