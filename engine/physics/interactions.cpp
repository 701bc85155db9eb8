// Interaction rows from bonds and dual bonds (IJNME 2016 eq. 27; CMAME 2017 §3, eq. 5;
// docs/theory.md §4).
#include "engine/physics/interactions.hpp"

#include <algorithm>
#include <cmath>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"

namespace dhpd {

namespace {

/// One neighbour of a row before it is written: its bonds in both directions (−1 when absent).
struct Pairing {
  std::int32_t other;
  BondId own, dual;
};

/// The neighbours of row i in index order, each once (dual bonds only for dual-horizon).
void pairings_of(std::size_t i, const RowInputs& in, std::vector<Pairing>& out) {
  out.clear();
  const auto& bonds = in.bonds;
  for (auto b = bonds.begin(i); b < bonds.end(i); ++b)
    out.push_back({bonds.neighbor[b], static_cast<BondId>(b), -1});
  if (in.model == ForceModel::DualHorizon)
    for (auto d = in.dual.begin(i); d < in.dual.end(i); ++d) {
      const BondId b = in.dual.bond[d];
      out.push_back({bonds.owner[b], -1, b});
    }
  std::sort(out.begin(), out.end(), [](const Pairing& a, const Pairing& b) {
    return a.other != b.other ? a.other < b.other : a.own > b.own;
  });
  // An own and a dual bond with the same neighbour (own first after the sort) become one entry.
  std::size_t kept = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (kept > 0 && out[kept - 1].other == out[k].other) {
      out[kept - 1].dual = out[k].dual;
      continue;
    }
    out[kept++] = out[k];
  }
  out.resize(kept);
}

/// ((1 + s0) |ξ|)² of an alive bond of `owner`, or NaN when it cannot break.
double exact_threshold(const RowInputs& in, std::int32_t owner, BondId b) {
  if (in.critical_stretch.empty() || in.particles.no_fail[owner] ||
      !std::isfinite(in.critical_stretch[owner]))
    return std::numeric_limits<double>::quiet_NaN();
  return bond_law::critical_length2(in.bonds.length[b], in.critical_stretch[owner]);
}

/// The float at or below t (NaN stays NaN): the fast test never misses a break.
float rounded_down(double t) {
  float f = static_cast<float>(t);
  if (static_cast<double>(f) > t) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

/// Writes row i at its start (which has room for `pairs`).
void write_row(InteractionList& il, std::size_t i, const RowInputs& in,
               const std::vector<Pairing>& pairs) {
  const auto& bonds = in.bonds;
  const auto self = static_cast<std::int32_t>(i);
  std::int64_t k = il.rows.start[i];
  for (const auto& e : pairs) {
    il.other[k] = e.other;
    il.own_bond[k] = e.own;
    il.dual_bond[k] = e.dual;
    // Both rows of a pair use the length of the bond owned by the lower index when both exist.
    const BondId shared = e.own < 0 ? e.dual : e.dual < 0 || self < e.other ? e.own : e.dual;
    il.inv_length[k] = 1.0 / bonds.length[shared];
    il.alive[k] = static_cast<std::uint8_t>((e.own >= 0 && bonds.intact[e.own] ? kOwnAlive : 0) |
                                            (e.dual >= 0 && bonds.intact[e.dual] ? kDualAlive : 0));
    refresh_entry(il, i, k, in);
    ++k;
  }
  il.rows.count[i] = static_cast<std::int32_t>(pairs.size());
}

void fit_arena(InteractionList& il) {
  const auto n = static_cast<std::size_t>(il.rows.arena);
  il.other.resize(n, 0);
  il.inv_length.resize(n, 0.0);
  il.coefficient.resize(n, 0.0);
  il.break_at.resize(n, kNeverBreaks);
  il.own_bond.resize(n, -1);
  il.dual_bond.resize(n, -1);
  il.alive.resize(n, 0);
}

template <class T>
std::size_t held(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace

std::size_t InteractionList::bytes() const {
  return rows.bytes() + held(other) + held(inv_length) + held(coefficient) + held(break_at) +
         held(own_bond) + held(dual_bond) + held(alive);
}

double entry_coefficient(const InteractionList& il, std::size_t i, std::int64_t k,
                         const RowInputs& in) {
  const auto& bonds = in.bonds;
  const auto j = static_cast<std::size_t>(il.other[k]);
  const double Vj = in.particles.volume[j];
  // Classical BB-PD: c = 2C on each own bond, no reactions (IJNME 2016 §3.1).
  const double own_factor = in.model == ForceModel::DualHorizon ? 1.0 : 2.0;
  double c = 0.0;
  if (il.alive[k] & kOwnAlive) {
    const auto b = il.own_bond[k];
    c += bond_law::coefficient(own_factor, in.micromodulus[i], bonds.weight[b], bonds.stiffness[b],
                               Vj, 1);
  }
  if (il.alive[k] & kDualAlive) {
    const auto b = il.dual_bond[k];
    c += bond_law::coefficient(1.0, in.micromodulus[j], bonds.weight[b], bonds.stiffness[b], Vj, 1);
  }
  return c;
}

float entry_break_at(const InteractionList& il, std::size_t i, std::int64_t k,
                     const RowInputs& in) {
  double t = std::numeric_limits<double>::quiet_NaN();
  if (il.alive[k] & kOwnAlive)
    t = exact_threshold(in, static_cast<std::int32_t>(i), il.own_bond[k]);
  if (il.alive[k] & kDualAlive) {
    const double d = exact_threshold(in, il.other[k], il.dual_bond[k]);
    if (std::isnan(t) || d < t) t = d;
  }
  return rounded_down(t);
}

std::int64_t InteractionList::find(std::size_t i, std::int32_t j) const {
  const auto first = other.begin() + begin(i), last = other.begin() + end(i);
  const auto it = std::lower_bound(first, last, j);
  return it != last && *it == j ? it - other.begin() : -1;
}

int break_entry(InteractionList& il, std::size_t i, std::int64_t k, double l2, const RowInputs& in,
                std::uint8_t* intact) {
  int broken = 0;
  auto& alive = il.alive[k];
  if ((alive & kOwnAlive) &&
      l2 >= exact_threshold(in, static_cast<std::int32_t>(i), il.own_bond[k])) {
    alive = static_cast<std::uint8_t>(alive & ~kOwnAlive);
    intact[il.own_bond[k]] = 0;
    broken = 1;
  }
  if ((alive & kDualAlive) && l2 >= exact_threshold(in, il.other[k], il.dual_bond[k]))
    alive = static_cast<std::uint8_t>(alive & ~kDualAlive);
  refresh_entry(il, i, k, in);
  return broken;
}

InteractionList build_interactions(const RowInputs& in) {
  const auto n = static_cast<std::int64_t>(in.bonds.particles());
  std::vector<std::int32_t> counts(static_cast<std::size_t>(n));
  const bool parallel = n >= kParallelMinParticles;
#pragma omp parallel if (parallel)
  {
    std::vector<Pairing> pairs;
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      pairings_of(static_cast<std::size_t>(i), in, pairs);
      counts[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(pairs.size());
    }
  }
  InteractionList il;
  il.rows = RowIndex::packed(counts);
  il.live = il.rows.arena;
  fit_arena(il);
#pragma omp parallel if (parallel)
  {
    std::vector<Pairing> pairs;
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      pairings_of(static_cast<std::size_t>(i), in, pairs);
      write_row(il, static_cast<std::size_t>(i), in, pairs);
    }
  }
  return il;
}

void rebuild_interaction_row(InteractionList& il, std::size_t i, const RowInputs& in) {
  std::vector<Pairing> pairs;
  pairings_of(i, in, pairs);
  const auto n = static_cast<std::int32_t>(pairs.size());
  il.live += n - il.rows.count[i];
  il.rows.make_room(i, n);
  fit_arena(il);
  write_row(il, i, in, pairs);
}

}  // namespace dhpd
