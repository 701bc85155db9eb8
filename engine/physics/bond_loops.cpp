// Bond loops (docs/theory.md §3, §4, §8, §9). Hot loops: flat arrays, no allocation, no virtual
// calls.
#include "engine/physics/bond_loops.hpp"
#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"
#include "engine/physics/force_kernel.hpp"

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

/// Damage of particle i (docs/theory.md §8): the weighted broken fraction of its own bonds.
void damage_of(const BondRows& b, ParticleStore& p, PartialVolume rule, std::size_t i) {
  // Every own bond intact: the two sums below take the same terms in the same order, so φ is 0
  // exactly, without the weights.
  auto k = b.begin(i);
  while (k < b.end(i) && (b.flags[k] & (kOwn | kOwnIntact)) != kOwn) ++k;
  if (k == b.end(i)) {
    p.damage[i] = 0.0;
    return;
  }
  double all = 0.0, intact = 0.0;
  for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
    const double w = bond_weight(p, rule, i, j, b.length(k)) * p.volume[j];
    all += w;
    intact += b.own_intact(k) ? w : 0.0;
  });
  p.damage[i] = all > 0.0 ? 1.0 - intact / all : 0.0;
}

/// Every row, or only `subset` when given, with the kernel build this CPU runs. With Fracture, a
/// row that broke one of its own bonds refreshes its damage at once: only row i writes i's own
/// bonds, so this stays race-free, and damage is always current without a pass over all bonds.
/// With Energy, row i's Σ_k c_k s_k² |ξ_k| goes to energy[i].
template <int Dim, bool Fracture, bool Energy>
std::int64_t force_rows(const BondRows& rows, const kernel::Breaking& w, ParticleStore& p,
                        const std::vector<std::int32_t>* subset, double* energy,
                        kernel::PackedPoints* points, const SideTask* side) {
  const bool has_side = side != nullptr && static_cast<bool>(*side);
  kernel::PackedPoints local;
  auto& packed_points = points ? *points : local;
  if (!packed_points.fresh) kernel::pack_points(p, packed_points.xyzv);
  packed_points.fresh = false;
  const auto& packed = packed_points.xyzv;
  const kernel::Fields x{
      {p.position[0].data(), p.position[1].data(), p.position[2].data()},
      {p.force_density[0].data(), p.force_density[1].data(), p.force_density[2].data()},
      energy,
      packed.data()};
  const kernel::RowArrays r(rows, p);
  const auto row = kernel::row_kernel<Dim, Fracture, Energy>(kernel::best_build());
  auto force_row = [&](std::int64_t i) {
    const std::int64_t broke = row(i, x, r, w);
    if constexpr (Fracture)
      if (broke) damage_of(*w.rows, p, w.constants->rule, static_cast<std::size_t>(i));
    return broke;
  };
  // A subset (an event's rows, a rank's share of a distributed run) in its order; rows are
  // independent, so large subsets take the thread team as the whole store does.
  std::int64_t broken = 0;
  const auto n = static_cast<std::int64_t>(subset ? subset->size() : p.size());
  const std::int32_t* slots = subset ? subset->data() : nullptr;
#pragma omp parallel reduction(+ : broken) if (n >= kParallelMinParticles)
  {
    if (has_side) {
#pragma omp single nowait
      (*side)();
    }
#pragma omp for schedule(dynamic, 512) nowait
    for (std::int64_t t = 0; t < n; ++t) broken += force_row(slots ? slots[t] : t);
  }
  return broken;
}

template <int Dim, bool Fracture>
std::int64_t segment_rows(BondRows& rows, const kernel::Breaking& w, ParticleStore& p,
                          const RowSegments& seg, const std::vector<double>& points,
                          const SideTask* side) {
  const kernel::Fields x{{p.position[0].data(), p.position[1].data(), p.position[2].data()},
                         {seg.force[0].data(), Dim > 1 ? seg.force[1].data() : nullptr,
                          Dim > 2 ? seg.force[2].data() : nullptr},
                         nullptr,
                         points.data()};
  kernel::RowArrays r(rows, p);
  r.start = seg.start;
  r.count = seg.count;
  const auto row = kernel::row_kernel<Dim, Fracture, false>(kernel::best_build());
  const auto n = static_cast<std::int64_t>(seg.rows.size());
  const bool has_side = side != nullptr && static_cast<bool>(*side);
  std::int64_t broken = 0;
#pragma omp parallel reduction(+ : broken) if (n >= kParallelMinParticles)
  {
    if (has_side) {
#pragma omp single nowait
      (*side)();
    }
#pragma omp for schedule(dynamic, 256) nowait
    for (std::int64_t t = 0; t < n; ++t) {
      const std::int64_t i = seg.rows[static_cast<std::size_t>(t)];
      const std::int64_t broke = row(i, x, r, w);
      if constexpr (Fracture)
        if (broke) damage_of(*w.rows, p, w.constants->rule, static_cast<std::size_t>(i));
      broken += broke;
    }
  }
  return broken;
}

/// force_rows with the energy output when `energy` is given (sized to the store first).
template <int Dim, bool Fracture>
std::int64_t force_rows_with(const BondRows& rows, const kernel::Breaking& w, ParticleStore& p,
                             const std::vector<std::int32_t>* subset, std::vector<double>* energy,
                             kernel::PackedPoints* points, const SideTask* side) {
  if (!energy) return force_rows<Dim, Fracture, false>(rows, w, p, subset, nullptr, points, side);
  energy->resize(p.size());
  return force_rows<Dim, Fracture, true>(rows, w, p, subset, energy->data(), points, side);
}

template <int Dim>
double row_energy(const BondRows& b, const BondConstants& c, std::size_t i) {
  const auto& p = c.particles;
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  double w = 0.0;
  for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
    if (!b.own_intact(k)) return;
    const double length = b.length(k);
    const double s = bond_law::stretch(bond_law::squared_length<Dim>(y, i, j), length);
    w += bond_law::energy_share(s, length, bond_weight(p, c.rule, i, j, length), b.own_factor(k),
                                p.volume[j]);
  });
  return 0.5 * c.micromodulus[i] * w;
}

template <int Dim>
void energy_rows(const BondRows& b, const BondConstants& c, std::vector<double>& out) {
  const auto n = static_cast<std::int64_t>(c.particles.size());
  out.assign(c.particles.size(), 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) out[i] = row_energy<Dim>(b, c, i);
}

}  // namespace

double strain_energy_total(const BondRows& b, const ParticleStore& p) {
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  const kernel::RowArrays r(b, p);
  std::vector<double> rows(p.size());
  with_dim(p.dim(), [&](auto d) {
    const auto energy = kernel::row_energy_kernel<d()>(kernel::best_build());
    each_row(p.size(), nullptr, [&](std::int64_t i) { rows[i] = energy(i, y, r); });
  });
  return strain_energy_of_row_sums(rows, p);
}

double strain_energy_of_row_sums(std::vector<double>& row_sums, const ParticleStore& p) {
  // V_i Σ_k ¼ c_k s_k² |ξ_k| per row; entries without an intact bond (c = 0) add nothing.
  for (std::size_t i = 0; i < p.size(); ++i) row_sums[i] = 0.25 * p.volume[i] * row_sums[i];
  return ordered_sum(row_sums);
}

void internal_force_density(const BondRows& b, ParticleStore& p,
                            const std::vector<std::int32_t>* rows, std::vector<double>* row_energy,
                            kernel::PackedPoints* points, const SideTask* side) {
  with_dim(p.dim(), [&](auto d) {
    force_rows_with<d(), false>(b, kernel::Breaking{}, p, rows, row_energy, points, side);
  });
}

std::int64_t force_and_break(BondRows& b, ParticleStore& p, const BondConstants& c,
                             std::vector<double>* row_energy, kernel::PackedPoints* points,
                             const SideTask* side, const std::vector<std::int32_t>* rows,
                             const kernel::StretchWatch& watch) {
  const kernel::Breaking w{&b, &c, watch};
  return with_dim(p.dim(), [&](auto d) {
    return force_rows_with<d(), true>(b, w, p, rows, row_energy, points, side);
  });
}

std::int64_t break_bonds(BondRows& b, ParticleStore& p, const BondConstants& c,
                         const std::vector<std::int32_t>* rows) {
  const auto n = static_cast<std::int64_t>(rows ? rows->size() : p.size());
  const std::int32_t* slots = rows ? rows->data() : nullptr;
  std::int64_t broken = 0;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : broken) if (n >= kParallelMinParticles)
  for (std::int64_t t = 0; t < n; ++t) {
    const auto row = static_cast<std::size_t>(slots ? slots[t] : t);
    int broke = 0;
    for (auto k = b.begin(row); k < b.end(row); ++k) {
      if (!(b.flags[k] & (kOwnIntact | kDualIntact))) continue;
      const auto j = static_cast<std::size_t>(b.other[k]);
      const double ratio2 =
          bond_law::stretch_ratio2(bond_law::squared_length(p, row, j), b.inverse_length(k));
      if (ratio2 >= b.break_ratio2[row]) broke += break_entry(b, row, k, ratio2, c);
    }
    if (broke) damage_of(b, p, c.rule, row);
    broken += broke;
  }
  return broken;
}

std::int64_t segment_forces(BondRows& b, ParticleStore& p, const BondConstants* c,
                            const RowSegments& seg, const std::vector<double>& points,
                            const SideTask* side, const kernel::StretchWatch& watch) {
  const kernel::Breaking w{&b, c, c ? watch : kernel::StretchWatch{}};
  return with_dim(p.dim(), [&](auto d) {
    return c ? segment_rows<d(), true>(b, w, p, seg, points, side)
             : segment_rows<d(), false>(b, w, p, seg, points, side);
  });
}

void strain_energy_density(const BondRows& b, const BondConstants& c, std::vector<double>& out) {
  with_dim(c.particles.dim(), [&](auto d) { energy_rows<d()>(b, c, out); });
}

double strain_energy_of_rows(const BondRows& b, const ParticleStore& p,
                             const std::vector<std::int32_t>& rows) {
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  const kernel::RowArrays r(b, p);
  return with_dim(p.dim(), [&](auto d) {
    const auto energy = kernel::row_energy_kernel<d()>(kernel::best_build());
    double sum = 0.0;
    for (const auto i : rows) sum += 0.25 * p.volume[i] * energy(i, y, r);
    return sum;
  });
}

namespace {
double stable_step_of(const BondRows& b, const ParticleStore& p, std::size_t i) {
  double stiffness = 0.0;
  for (auto k = b.begin(i); k < b.end(i); ++k)
    stiffness += std::abs(static_cast<double>(b.stiffness[k]) * b.stiffness_scale *
                          p.volume[static_cast<std::size_t>(b.other[k])]) *
                 b.inverse_length(k);
  return stiffness > 0.0 ? std::sqrt(2.0 * p.density[i] / stiffness)
                         : std::numeric_limits<double>::infinity();
}
}  // namespace

void compute_damage(const BondRows& b, ParticleStore& p, PartialVolume rule,
                    const std::vector<std::int32_t>* rows) {
  each_row(p.size(), rows,
           [&](std::int64_t i) { damage_of(b, p, rule, static_cast<std::size_t>(i)); });
}

void horizon_quadrature(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                        const Section& section, std::vector<double>& out) {
  out.assign(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    double sum = p.volume[i];
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      sum += bond_weight(p, rule, i, j, b.length(k)) * p.volume[j];
    });
    out[i] = sum / section.horizon_volume(p.horizon[i]);
  }
}

void particle_time_steps(const BondRows& il, const ParticleStore& p, std::vector<double>& out,
                         const std::vector<std::int32_t>* rows) {
  out.resize(p.size(), std::numeric_limits<double>::infinity());
  each_row(p.size(), rows, [&](std::int64_t i) {
    out[static_cast<std::size_t>(i)] = stable_step_of(il, p, static_cast<std::size_t>(i));
  });
}

double critical_time_step(const BondRows& il, const ParticleStore& p) {
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
  // Block-wise over fixed blocks: serial, so identical for any thread count.
  double total = 0.0;
  constexpr auto block = static_cast<std::size_t>(kOrderedSumBlock);
  for (std::size_t s = 0; s < values.size(); s += block) {
    double part = 0.0;
    const std::size_t e = std::min(values.size(), s + block);
    for (std::size_t k = s; k < e; ++k) part += values[k];
    total += part;
  }
  return total;
}

}  // namespace dhpd
