// Bond rows: construction, renumbering and the replacement of own bonds (docs/theory.md §2, §18;
// §7 = CMAME 2017 eq. A.1 and App. A; §8 pre-cracks).
#include "engine/discretization/bonds.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <omp.h>

#include "engine/base/errors.hpp"
#include "engine/base/parallel.hpp"
#include "engine/discretization/length_table.hpp"
#include "engine/discretization/neighbor_search.hpp"
#include "geometry/intersection.hpp"

namespace dhpd {

double partial_volume_factor(PartialVolume rule, int dim, double distance, double horizon,
                             double r_j) {
  if (rule == PartialVolume::Exact)
    return geometry::partial_volume_fraction(dim, distance, horizon, r_j);
  // A lattice neighbour at exactly δ (δ = 3Δx, as the papers write it) is inside: the distance
  // computed from positions can land an ulp above δ, which would drop a whole shell of bonds
  // (a 1D bar at δ = 3Δx lost a third of its stiffness, docs/theory.md §7).
  if (distance > horizon * (1.0 + kHorizonTieTolerance)) return 0.0;
  if (rule == PartialVolume::None) return 1.0;
  if (distance <= horizon - r_j) return 1.0;
  return (horizon + r_j - distance) / (2.0 * r_j);
}

double bond_weight(const ParticleStore& p, PartialVolume rule, std::size_t owner,
                   std::size_t neighbor, double length) {
  const double r = rule == PartialVolume::Exact ? p.radius[neighbor] : 0.5 * p.spacing[neighbor];
  return partial_volume_factor(rule, p.dim(), length, p.horizon[owner], r);
}

void set_particle_radii(ParticleStore& p, const Section& section) {
  for (std::size_t i = 0; i < p.size(); ++i)
    p.radius[i] = section.equal_measure_radius(p.volume[i]);
}

double inverse_reference_length(const ParticleStore& p, std::size_t i, std::size_t j) {
  double d2 = 0.0;
  for (int a = 0; a < p.dim(); ++a) {
    const double d = p.reference_position[a][j] - p.reference_position[a][i];
    d2 += d * d;
  }
  return 1.0 / std::sqrt(d2);
}

BondRowBuilder::BondRowBuilder(const ParticleStore& p, PartialVolume rule,
                               const std::vector<geometry::Crack>& cracks, double reach)
    : p_(p), pv_(rule), reach_(reach), cracks_(cracks) {
  for (const auto& c : cracks) {
    geometry::Vec3 lo = c.points.front(), hi = c.points.front();
    for (const auto& q : c.points)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
    crack_boxes_.emplace_back(lo, hi);
  }
}

double BondRowBuilder::exact_reach(const ParticleStore& p, PartialVolume rule) {
  if (rule != PartialVolume::Exact) return 0.0;
  double r_max = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.radius[i] > 0.0))
      throw EngineError(
          "partial_volume exact needs every particle radius > 0 (set_particle_radii)");
    r_max = std::max(r_max, p.radius[i]);
  }
  return r_max;
}

double BondRowBuilder::search_radius(std::size_t i) const {
  return (p_.horizon[i] + reach_) * (1.0 + 1e-9);
}

bool BondRowBuilder::bonded(std::size_t i, std::size_t j) const {
  if (i == j) return false;
  const double inv = inverse_reference_length(p_, i, j);
  if (!std::isfinite(inv)) return false;  // coincident particles (refused at load time)
  if (!(bond_weight(p_, pv_, i, j, 1.0 / inv) > 0.0)) return false;
  // One crossing test per pair, from the lower index: both bonds of a pair see the same answer.
  const auto lo = std::min(i, j), hi = std::max(i, j);
  const auto a = point_of(p_.reference_position, lo), b = point_of(p_.reference_position, hi);
  for (std::size_t c = 0; c < cracks_.size(); ++c) {
    const auto& [box_lo, box_hi] = crack_boxes_[c];
    bool apart = false;  // the segment's box and the crack's are disjoint (touching is not)
    for (int d = 0; d < p_.dim(); ++d)
      apart = apart || std::max(a[d], b[d]) < box_lo[d] || std::min(a[d], b[d]) > box_hi[d];
    if (!apart && geometry::crosses(cracks_[c], a, b, p_.dim())) return false;
  }
  return true;
}

bool BondRowBuilder::bonded_back(std::size_t i, std::size_t j) const {
  return bond_weight(p_, pv_, j, i, 1.0 / inverse_reference_length(p_, i, j)) > 0.0;
}

void BondRowBuilder::keep_bonds(std::size_t i, std::vector<std::int32_t>& cand) const {
  std::size_t kept = 0;
  for (const auto j : cand)
    if (bonded(i, static_cast<std::size_t>(j))) cand[kept++] = j;
  cand.resize(kept);
}

std::int64_t BondRows::find(std::size_t i, std::int32_t j) const {
  const auto first = other.begin() + begin(i), last = other.begin() + end(i);
  const auto it = std::lower_bound(first, last, j);
  return it != last && *it == j ? it - other.begin() : -1;
}

std::int32_t BondRows::own_count(std::size_t i) const {
  std::int32_t n = 0;
  for (auto k = begin(i); k < end(i); ++k) n += flags[k] & kOwn ? 1 : 0;
  return n;
}

namespace {
/// Resizes v to n entries; storage that must grow takes half as much again, unless it was empty
/// (a from-scratch build is exact).
template <class T>
void fit_to(std::vector<T>& v, std::size_t n, T fill) {
  if (n > v.capacity() && v.capacity() > 0) v.reserve(n + n / 2);
  v.resize(n, fill);
}

}  // namespace

void BondRows::fit_arena() {
  const auto n = static_cast<std::size_t>(rows.arena);
  fit_to(other, n, std::int32_t{-1});
  fit_to(length_index, n, std::int32_t{0});
  fit_to(flags, n, std::uint8_t{0});
  fit_to(stiffness, n, 0.0f);
  if (!factor.empty()) fit_to(factor, n, 1.0f);
  if (!dilatation_factor.empty()) fit_to(dilatation_factor, n, 1.0f);
}

namespace {
template <class T>
std::size_t held(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

/// One table from the threads' tables of build_bond_rows, whose rows hold their `own[i]` own
/// bonds first (in neighbour order, indices into the table of thread team_of[i]), then dual-only
/// entries without an index: team t's values follow those of the teams before it, own entries
/// shift by as much, a dual-only entry takes the index of its own side, and the table is made
/// canonical.
void merge_team_tables(BondRows& b, const std::vector<std::int32_t>& own,
                       const std::vector<std::vector<double>>& tables,
                       const std::vector<std::uint8_t>& team_of) {
  std::vector<std::int32_t> offset;
  b.inverse_lengths.clear();
  for (const auto& t : tables) {
    offset.push_back(static_cast<std::int32_t>(b.inverse_lengths.size()));
    b.inverse_lengths.insert(b.inverse_lengths.end(), t.begin(), t.end());
  }
  const auto n = static_cast<std::int64_t>(own.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    const auto s = b.begin(static_cast<std::size_t>(i));
    for (auto k = s; k < s + own[i]; ++k) b.length_index[k] += offset[team_of[i]];
  }
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i)
    for (auto k = b.begin(i) + own[i]; k < b.end(i); ++k) {  // dual-only: its own side in row j
      const auto j = static_cast<std::size_t>(b.other[k]);
      const auto first = b.other.begin() + b.begin(j), last = first + own[j];
      const auto at = std::lower_bound(first, last, static_cast<std::int32_t>(i)) - b.other.begin();
      b.length_index[k] = b.length_index[at];
    }
  canonical_lengths(b.inverse_lengths, b.length_index, b.other);
}

/// Sorts the entries of row i by `other` (rows of a few hundred entries: an index sort).
void sort_row(BondRows& b, std::size_t i, std::vector<std::int64_t>& order,
              std::vector<std::int32_t>& o, std::vector<std::int32_t>& len,
              std::vector<std::uint8_t>& fl) {
  const auto s = b.begin(i), n = b.end(i) - s;
  order.resize(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), s);
  std::sort(order.begin(), order.end(),
            [&](std::int64_t x, std::int64_t y) { return b.other[x] < b.other[y]; });
  o.clear(), len.clear(), fl.clear();
  for (const auto k : order)
    o.push_back(b.other[k]), len.push_back(b.length_index[k]), fl.push_back(b.flags[k]);
  std::copy(o.begin(), o.end(), b.other.begin() + s);
  std::copy(len.begin(), len.end(), b.length_index.begin() + s);
  std::copy(fl.begin(), fl.end(), b.flags.begin() + s);
}
}  // namespace

std::size_t BondRows::bytes() const {
  return rows.bytes() + held(other) + held(length_index) + held(inverse_lengths) + held(flags) +
         held(factor) + held(dilatation_factor) + held(stiffness) + held(break_ratio2);
}

BondRows build_bond_rows(const ParticleStore& p, PartialVolume pv,
                         const std::vector<geometry::Crack>& cracks) {
  const auto n = static_cast<std::int64_t>(p.size());
  const BondRowBuilder builder(p, pv, cracks, BondRowBuilder::exact_reach(p, pv));
  NeighborSearch search(p.reference_position, p.dim());
  std::vector<std::int32_t> own(static_cast<std::size_t>(n), 0), dual_only(own);
  const bool parallel = n >= kParallelMinParticles;
  // Pass 1: own bonds per row, and the dual-only entries they give their neighbours' rows (a bond
  // i→j whose pair has no bond j→i).
#pragma omp parallel if (parallel)
  {
    std::vector<std::int32_t> cand;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      search.within(u, builder.search_radius(u), cand);
      builder.keep_bonds(u, cand);
      own[u] = static_cast<std::int32_t>(cand.size());
      for (const auto j : cand)
        if (!builder.bonded_back(u, static_cast<std::size_t>(j))) {
#pragma omp atomic
          ++dual_only[static_cast<std::size_t>(j)];
        }
    }
  }
  std::vector<std::int32_t> counts(own.size());
  std::int64_t own_total = 0;
  for (std::size_t i = 0; i < own.size(); ++i)
    counts[i] = own[i] + dual_only[i], own_total += own[i];
  BondRows b;
  b.rows = RowIndex::packed(counts);
  b.fit_arena();
  b.live = b.rows.arena;
  b.own_bonds = own_total;
  b.break_ratio2.assign(own.size(), HUGE_VAL);       // set by engine/physics/interactions
  std::fill(dual_only.begin(), dual_only.end(), 0);  // now the cursors of the dual-only entries
  // Pass 2: each row's own bonds at its start, in neighbour order; a dual-only entry goes after
  // the own ones of its row, in the order threads reach it (pass 3 sorts the rows). Each thread
  // interns the lengths of the own bonds of its rows in a table of its own; `team_of` notes which
  // thread wrote a row, and dual-only entries take their index from their own side afterwards.
  const int teams = parallel ? std::min(omp_get_max_threads(), 255) : 1;
  std::vector<std::vector<double>> tables(static_cast<std::size_t>(teams));
  std::vector<std::uint8_t> team_of(own.size(), 0);
#pragma omp parallel num_threads(teams) if (parallel)
  {
    std::vector<std::int32_t> cand;
    const int team = omp_get_thread_num();
    LengthInterner lengths(tables[static_cast<std::size_t>(team)]);
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      search.within(u, builder.search_radius(u), cand);
      builder.keep_bonds(u, cand);
      auto k = b.begin(u);
      team_of[u] = static_cast<std::uint8_t>(team);
      for (const auto j : cand) {
        const auto v = static_cast<std::size_t>(j);
        const double inv = inverse_reference_length(p, u, v);
        const bool pair = builder.bonded_back(u, v);
        b.other[k] = j, b.length_index[k] = lengths.index_of(inv);
        b.flags[k++] =
            static_cast<std::uint8_t>(kOwn | kOwnIntact | (pair ? kDual | kDualIntact : 0));
        if (pair) continue;
        std::int32_t slot = 0;
#pragma omp atomic capture
        slot = dual_only[v]++;
        const auto e = b.begin(v) + own[v] + slot;
        b.other[e] = static_cast<std::int32_t>(i);
        b.flags[e] = kDual | kDualIntact;
      }
    }
  }
  merge_team_tables(b, own, tables, team_of);
  // Pass 3: rows in neighbour order (only rows that received dual-only entries need it).
#pragma omp parallel if (parallel)
  {
    std::vector<std::int64_t> order;
    std::vector<std::int32_t> o, len;
    std::vector<std::uint8_t> fl;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < n; ++i)
      if (dual_only[static_cast<std::size_t>(i)] > 0)
        sort_row(b, static_cast<std::size_t>(i), order, o, len, fl);
  }
  return b;
}

}  // namespace dhpd
