// Small builders shared by the engine tests and those above them (test-only code lives here, not
// in the engine): bond rows built from scratch, random clouds, lattice stores.
#pragma once
#include <cmath>
#include <random>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/interactions.hpp"
#include "engine/physics/material_law.hpp"
#include "engine/physics/multi_horizon.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"

namespace dhpd::test {

/// The bond rows of a store built from scratch, with the constants their stiffness came from.
struct Assembly {
  BondRows bonds;
  ForceModel model = ForceModel::DualHorizon;
  PartialVolume rule = PartialVolume::None;
  std::vector<double> C;
  std::vector<double> s0;     ///< empty: rows that never break
  std::vector<double> alpha;  ///< multi-horizon α (empty for the other models)

  BondConstants constants(const ParticleStore& p) const { return {model, rule, p, C, s0, alpha}; }
  /// Derives every entry's stiffness and every row's break threshold again (after editing C, s0,
  /// the flags or the factors).
  void refresh(const ParticleStore& p, bool choose_scale = false) {
    refresh_rows(bonds, constants(p), choose_scale);
  }
};

inline Assembly assemble(const ParticleStore& p, ForceModel model, PartialVolume pv,
                         const Material& m, const Section& s) {
  Assembly a;
  a.model = model;
  a.rule = pv;
  a.bonds = build_bond_rows(p, pv, {});
  a.C.resize(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) a.C[i] = micromodulus(m, s, p.horizon[i]);
  if (model == ForceModel::MultiHorizon) a.alpha = interaction_scales(a.bonds, p, a.C);
  a.refresh(p, true);
  return a;
}

/// A section of dimension `dim` (plane mode, thickness in 2D, area in 1D).
inline Section section_of(int dim, PlaneMode plane = PlaneMode::Strain, double thickness = 1e-3,
                          double area = 1e-6) {
  Section s;
  s.dim = dim;
  s.plane = plane;
  s.thickness = thickness;
  s.area = area;
  return s;
}

/// A random cloud in the unit cube (first `dim` axes) with spacings spread over [h, ratio·h].
inline ParticleStore random_cloud(int dim, std::size_t n, double h, double ratio, double factor,
                                  unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ParticleStore p(dim);
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < dim; ++a) p.reference_position[a][i] = unit(rng);
    p.spacing[i] = h * std::pow(ratio, unit(rng));
    p.horizon[i] = factor * p.spacing[i];
    p.volume[i] = std::pow(p.spacing[i], dim);
    p.density[i] = 1000.0 * (1.0 + unit(rng));
    for (int a = 0; a < dim; ++a) {
      p.displacement[a][i] = 1e-3 * (unit(rng) - 0.5);
      p.position[a][i] = p.reference_position[a][i] + p.displacement[a][i];
    }
  }
  Section s;
  s.dim = dim;
  set_particle_radii(p, s);
  return p;
}

/// A store filled from a lattice of one part (spacing dx over [0, L] per axis).
inline ParticleStore lattice_store(int dim, int cells, double dx, double factor, const Section& s) {
  geometry::Box box;
  for (int a = 0; a < dim; ++a) box.max[a] = cells * dx;
  const auto pts = geometry::fill_lattice({{box, dx, 0}}, dim);
  ParticleStore p(dim);
  p.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (int a = 0; a < 3; ++a) p.reference_position[a][i] = p.position[a][i] = pts.position[i][a];
    p.spacing[i] = dx;
    p.horizon[i] = factor * dx;
    p.volume[i] = s.volume_of_cell(pts.cell_measure[i]);
    p.density[i] = 1000.0;
    p.id[i] = static_cast<std::int32_t>(i);
  }
  set_particle_radii(p, s);
  return p;
}

/// A store filled from any point set (lattice, mesh or file): horizon = factor × spacing.
inline ParticleStore store_from_points(const geometry::PointSet& pts, int dim, double factor,
                                       const Section& s) {
  ParticleStore p(dim);
  p.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (int a = 0; a < 3; ++a) p.reference_position[a][i] = p.position[a][i] = pts.position[i][a];
    p.spacing[i] = pts.spacing[i];
    p.horizon[i] = factor * pts.spacing[i];
    p.volume[i] = s.volume_of_cell(pts.cell_measure[i]);
    p.density[i] = 1000.0;
    p.id[i] = static_cast<std::int32_t>(i);
  }
  set_particle_radii(p, s);
  return p;
}

/// |Σ F| / Σ |F| and |Σ y × F| / Σ |y||F| of the current force densities (F = f V).
struct Balance {
  double linear = 0, angular = 0;
};

inline Balance momentum_balance(const ParticleStore& p) {
  double sum_f[3] = {0, 0, 0}, sum_m[3] = {0, 0, 0}, scale_f = 0, scale_m = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double F[3] = {p.force_density[0][i] * p.volume[i], p.force_density[1][i] * p.volume[i],
                         p.force_density[2][i] * p.volume[i]};
    const double y[3] = {p.position[0][i], p.position[1][i], p.position[2][i]};
    const double M[3] = {y[1] * F[2] - y[2] * F[1], y[2] * F[0] - y[0] * F[2],
                         y[0] * F[1] - y[1] * F[0]};
    const double fn = std::sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2]);
    for (int a = 0; a < 3; ++a) sum_f[a] += F[a], sum_m[a] += M[a];
    scale_f += fn;
    scale_m += fn * std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
  }
  auto len = [](const double* v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  return {len(sum_f) / scale_f, len(sum_m) / scale_m};
}

inline void set_displacement(ParticleStore& p, int a, std::size_t i, double u) {
  p.displacement[a][i] = u;
  p.position[a][i] = p.reference_position[a][i] + u;
}

}  // namespace dhpd::test
