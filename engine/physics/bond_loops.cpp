// Bond loops (docs/theory.md §3, §4, §8, §9). Hot loops: flat arrays, no allocation, no virtual
// calls.
#include "engine/physics/bond_loops.hpp"
#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dhpd {
namespace {

/// Calls f(i) for the particles in `rows`, serially (an event's few touched rows), or for all n
/// particles in parallel when `rows` is null.
template <class F>
void each_row(std::size_t n, const std::vector<std::int32_t>* rows, F&& f) {
  if (rows) {
    for (const auto i : *rows) f(static_cast<std::int64_t>(i));
    return;
  }
  const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) if (count >= kParallelMinParticles)
  for (std::int64_t i = 0; i < count; ++i) f(i);
}

/// Force density of row i (no allocation, one gather over the row).
template <int Dim>
inline void force_row(std::int64_t i, const double* const y[3], double* const f[3],
                      const std::int64_t* start, const std::int32_t* count,
                      const std::int32_t* other, const double* inv_len, const double* coef) {
  double yi[Dim], acc[Dim];
  for (int a = 0; a < Dim; ++a) yi[a] = y[a][i], acc[a] = 0.0;
  const std::int64_t row_end = start[i] + count[i];
  for (std::int64_t k = start[i]; k < row_end; ++k) {
    const std::int32_t j = other[k];
    double dx[Dim], l2 = 0.0;
    for (int a = 0; a < Dim; ++a) dx[a] = y[a][j] - yi[a], l2 += dx[a] * dx[a];
    const double scale = bond_law::force_factor(coef[k], inv_len[k], l2);
    for (int a = 0; a < Dim; ++a) acc[a] += scale * dx[a];
  }
  for (int a = 0; a < Dim; ++a) f[a][i] = acc[a];
}

/// Every row, or only `subset` when given.
template <int Dim>
void force_rows(const InteractionList& il, ParticleStore& p,
                const std::vector<std::int32_t>* subset) {
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  double* const f[3] = {p.force_density[0].data(), p.force_density[1].data(),
                        p.force_density[2].data()};
  const auto* start = il.rows.start.data();
  const auto* count = il.rows.count.data();
  const auto* other = il.other.data();
  const auto* inv_len = il.inv_length.data();
  const auto* coef = il.coefficient.data();
  each_row(p.size(), subset,
           [&](std::int64_t i) { force_row<Dim>(i, y, f, start, count, other, inv_len, coef); });
}

template <int Dim>
std::int64_t break_rows(BondList& bonds, InteractionList& il, const ParticleStore& p,
                        const std::vector<double>& s0) {
  const auto n = static_cast<std::int64_t>(p.size());
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  std::int64_t broken = 0;
#pragma omp parallel for schedule(static) reduction(+ : broken) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    if (p.no_fail[i]) continue;
    const double limit = s0[i];
    for (auto b = bonds.begin(i); b < bonds.end(i); ++b) {
      if (!bonds.intact[b]) continue;
      const double l2 = bond_law::squared_length<Dim>(y, static_cast<std::size_t>(i),
                                                      static_cast<std::size_t>(bonds.neighbor[b]));
      if (!bond_law::reaches_critical_stretch(l2, bonds.length[b], limit)) continue;
      bonds.intact[b] = 0;
      il.coefficient[il.own_slot[b]] = 0.0;
      if (il.dual_slot[b] >= 0) il.coefficient[il.dual_slot[b]] = 0.0;
      ++broken;
    }
  }
  return broken;
}

template <int Dim>
double row_energy(const BondList& bonds, const ParticleStore& p, const std::vector<double>& C,
                  std::size_t i) {
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  double w = 0.0;
  for (auto b = bonds.begin(i); b < bonds.end(i); ++b) {
    if (!bonds.intact[b]) continue;
    const auto j = static_cast<std::size_t>(bonds.neighbor[b]);
    const double s = bond_law::stretch(bond_law::squared_length<Dim>(y, i, j), bonds.length[b]);
    w += bond_law::energy_share(s, bonds.length[b], bonds.weight[b], bonds.stiffness[b],
                                p.volume[j]);
  }
  return 0.5 * C[i] * w;
}

template <int Dim>
void energy_rows(const BondList& bonds, const ParticleStore& p, const std::vector<double>& C,
                 std::vector<double>& out) {
  const auto n = static_cast<std::int64_t>(p.size());
  out.assign(p.size(), 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) out[i] = row_energy<Dim>(bonds, p, C, i);
}

template <int Dim>
double energy_of(const BondList& bonds, const ParticleStore& p, const std::vector<double>& C,
                 const std::vector<std::int32_t>& rows) {
  double sum = 0.0;
  for (const auto i : rows)
    sum += p.volume[i] * row_energy<Dim>(bonds, p, C, static_cast<std::size_t>(i));
  return sum;
}

}  // namespace

void internal_force_density(const InteractionList& il, ParticleStore& p,
                            const std::vector<std::int32_t>* rows) {
  with_dim(p.dim(), [&](auto d) { force_rows<d()>(il, p, rows); });
}

std::int64_t break_bonds(BondList& bonds, InteractionList& il, const ParticleStore& p,
                         const std::vector<double>& s0) {
  return with_dim(p.dim(), [&](auto d) { return break_rows<d()>(bonds, il, p, s0); });
}

void strain_energy_density(const BondList& bonds, const ParticleStore& p,
                           const std::vector<double>& C, std::vector<double>& out) {
  with_dim(p.dim(), [&](auto d) { energy_rows<d()>(bonds, p, C, out); });
}

double strain_energy_of_rows(const BondList& bonds, const ParticleStore& p,
                             const std::vector<double>& C, const std::vector<std::int32_t>& rows) {
  return with_dim(p.dim(), [&](auto d) { return energy_of<d()>(bonds, p, C, rows); });
}

namespace {
void damage_of(const BondList& bonds, ParticleStore& p, std::size_t i) {
  double all = 0.0, intact = 0.0;
  for (auto b = bonds.begin(i); b < bonds.end(i); ++b) {
    const double w = bonds.weight[b] * p.volume[bonds.neighbor[b]];
    all += w;
    intact += bonds.intact[b] * w;
  }
  p.damage[i] = all > 0.0 ? 1.0 - intact / all : 0.0;
}

double stable_step_of(const InteractionList& il, const ParticleStore& p, std::size_t i) {
  double stiffness = 0.0;
  for (auto k = il.begin(i); k < il.end(i); ++k)
    stiffness += std::abs(il.coefficient[k]) * il.inv_length[k];
  return stiffness > 0.0 ? std::sqrt(2.0 * p.density[i] / stiffness)
                         : std::numeric_limits<double>::infinity();
}
}  // namespace

void compute_damage(const BondList& bonds, ParticleStore& p,
                    const std::vector<std::int32_t>* rows) {
  each_row(p.size(), rows,
           [&](std::int64_t i) { damage_of(bonds, p, static_cast<std::size_t>(i)); });
}

void horizon_quadrature(const BondList& bonds, const ParticleStore& p, const Section& section,
                        std::vector<double>& out) {
  out.assign(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    double sum = p.volume[i];
    for (auto b = bonds.begin(i); b < bonds.end(i); ++b)
      sum += bonds.weight[b] * p.volume[bonds.neighbor[b]];
    out[i] = sum / section.horizon_volume(p.horizon[i]);
  }
}

void particle_time_steps(const InteractionList& il, const ParticleStore& p,
                         std::vector<double>& out, const std::vector<std::int32_t>* rows) {
  out.resize(p.size(), std::numeric_limits<double>::infinity());
  each_row(p.size(), rows, [&](std::int64_t i) {
    out[static_cast<std::size_t>(i)] = stable_step_of(il, p, static_cast<std::size_t>(i));
  });
}

double critical_time_step(const InteractionList& il, const ParticleStore& p) {
  std::vector<double> steps;
  particle_time_steps(il, p, steps);
  return smallest(steps);
}

double smallest(const std::vector<double>& values) {
  double least = std::numeric_limits<double>::infinity();
  for (const double v : values) least = std::min(least, v);
  return least;
}

double ordered_sum(const std::vector<double>& values) {
  // Block-wise over fixed blocks of 4096: serial, so identical for any thread count.
  double total = 0.0;
  constexpr std::size_t block = 4096;
  for (std::size_t s = 0; s < values.size(); s += block) {
    double part = 0.0;
    const std::size_t e = std::min(values.size(), s + block);
    for (std::size_t k = s; k < e; ++k) part += values[k];
    total += part;
  }
  return total;
}

}  // namespace dhpd
