// Bond and dual-bond construction (docs/theory.md §2; §7 = CMAME 2017 eq. A.1 and App. A; §8
// pre-cracks).
#include "engine/discretization/bonds.hpp"
#include "engine/base/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/base/errors.hpp"
#include "engine/discretization/neighbor_search.hpp"
#include "geometry/intersection.hpp"

namespace dhpd {

double partial_volume_factor(PartialVolume rule, int dim, double distance, double horizon,
                             double r_j) {
  if (rule == PartialVolume::Exact)
    return geometry::partial_volume_fraction(dim, distance, horizon, r_j);
  if (distance > horizon) return 0.0;
  if (rule == PartialVolume::None) return 1.0;
  if (distance <= horizon - r_j) return 1.0;
  return (horizon + r_j - distance) / (2.0 * r_j);
}

void set_particle_radii(ParticleStore& p, const Section& section) {
  for (std::size_t i = 0; i < p.size(); ++i)
    p.radius[i] = section.equal_measure_radius(p.volume[i]);
}

namespace {

bool crosses_any(const std::vector<geometry::Crack>& cracks, const geometry::Vec3& a,
                 const geometry::Vec3& b, int dim) {
  for (const auto& c : cracks)
    if (geometry::crosses(c, a, b, dim)) return true;
  return false;
}

}  // namespace

BondRowBuilder::BondRowBuilder(const ParticleStore& p, PartialVolume rule,
                               const std::vector<geometry::Crack>& cracks, double reach)
    : p_(p), pv_(rule), reach_(reach), cracks_(cracks) {}

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

void BondRowBuilder::keep_bonds(std::size_t i, std::vector<std::int32_t>& cand,
                                std::vector<double>* len, std::vector<double>* w) const {
  const auto& X = p_.reference_position;
  const double delta = p_.horizon[i];
  std::size_t kept = 0;
  const auto xi = point_of(X, i);
  for (const auto j : cand) {
    double d2 = 0.0;
    for (int a = 0; a < p_.dim(); ++a) {
      const double d = X[a][j] - X[a][i];
      d2 += d * d;
    }
    const double dist = std::sqrt(d2);
    const double r_j = pv_ == PartialVolume::Exact ? p_.radius[j] : 0.5 * p_.spacing[j];
    const double beta = partial_volume_factor(pv_, p_.dim(), dist, delta, r_j);
    if (beta <= 0.0 || dist == 0.0) continue;
    if (!cracks_.empty() && crosses_any(cracks_, xi, point_of(X, j), p_.dim())) continue;
    cand[kept++] = j;
    if (len) len->push_back(dist), w->push_back(beta);
  }
  cand.resize(kept);
}

void BondList::fit_arena() {
  const auto n = static_cast<std::size_t>(rows.arena);
  owner.resize(n, -1);
  neighbor.resize(n, -1);
  length.resize(n, 0.0);
  weight.resize(n, 0.0);
  intact.resize(n, 0);
  stiffness.resize(n, 1.0);
}

BondList build_bonds(const ParticleStore& p, PartialVolume pv,
                     const std::vector<geometry::Crack>& cracks) {
  const std::size_t n = p.size();
  const BondRowBuilder rows(p, pv, cracks, BondRowBuilder::exact_reach(p, pv));
  NeighborSearch search(p.reference_position, p.dim());
  std::vector<std::int32_t> counts(n, 0);
  // Pass 1: count each row (parallel, independent rows).
#pragma omp parallel if (static_cast <std::int64_t>(n) >= kParallelMinParticles)
  {
    std::vector<std::int32_t> cand;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      const auto u = static_cast<std::size_t>(i);
      search.within(u, rows.search_radius(u), cand);
      rows.keep_bonds(u, cand, nullptr, nullptr);
      counts[u] = static_cast<std::int32_t>(cand.size());
    }
  }
  std::int64_t total = 0;
  for (const auto c : counts) total += c;
  if (total > static_cast<std::int64_t>(INT32_MAX))
    throw EngineError("more than 2^31 bonds: not supported by 32-bit bond ids");
  BondList b;
  b.rows = RowIndex::packed(counts);
  b.fit_arena();
  std::fill(b.intact.begin(), b.intact.end(), 1);
  b.live = total;
  // Pass 2: fill each row at its start (same candidates, same order: deterministic).
#pragma omp parallel if (static_cast <std::int64_t>(n) >= kParallelMinParticles)
  {
    std::vector<std::int32_t> cand;
    std::vector<double> len, w;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      const auto u = static_cast<std::size_t>(i);
      len.clear(), w.clear();
      search.within(u, rows.search_radius(u), cand);
      rows.keep_bonds(u, cand, &len, &w);
      const auto o = static_cast<std::size_t>(b.begin(u));
      for (std::size_t k = 0; k < cand.size(); ++k) {
        b.owner[o + k] = static_cast<std::int32_t>(i);
        b.neighbor[o + k] = cand[k];
        b.length[o + k] = len[k];
        b.weight[o + k] = w[k];
      }
    }
  }
  return b;
}

DualList build_dual(const BondList& bonds) {
  const std::size_t n = bonds.particles();
  std::vector<std::int32_t> counts(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (auto b = bonds.begin(i); b < bonds.end(i); ++b)
      ++counts[static_cast<std::size_t>(bonds.neighbor[b])];
  DualList d;
  d.rows = RowIndex::packed(counts);
  d.bond.resize(static_cast<std::size_t>(d.rows.arena));
  std::fill(d.rows.count.begin(), d.rows.count.end(), 0);
  // Slots in increasing id order: every dual row comes out sorted by bond id.
  for (std::size_t b = 0; b < bonds.slots(); ++b) {
    const auto j = bonds.neighbor[b];
    if (j < 0) continue;
    auto& c = d.rows.count[static_cast<std::size_t>(j)];
    d.bond[static_cast<std::size_t>(d.rows.start[static_cast<std::size_t>(j)] + c++)] =
        static_cast<BondId>(b);
  }
  return d;
}

void DualList::add(std::size_t j, BondId b) {
  const auto old_start = rows.start[j];
  const auto c = rows.count[j];
  const auto s = rows.make_room(j, c + 1);
  if (bond.size() < static_cast<std::size_t>(rows.arena))
    bond.resize(static_cast<std::size_t>(rows.arena), -1);
  if (s != old_start) std::copy_n(bond.begin() + old_start, c, bond.begin() + s);
  bond[static_cast<std::size_t>(s + c)] = b;
  ++rows.count[j];
}

void DualList::remove(std::size_t j, BondId b) {
  const auto first = bond.begin() + begin(j), last = bond.begin() + end(j);
  const auto it = std::find(first, last, b);
  if (it == last) throw EngineError("dual list: bond not found in the dual row of its neighbour");
  std::copy(it + 1, last, it);
  --rows.count[j];
}

BondList renumbered_bonds(const BondList& bonds, const std::vector<std::int32_t>& order,
                          const std::vector<std::int32_t>& new_index) {
  const std::size_t n = order.size();
  BondList b;
  std::vector<std::int32_t> counts(n);
  for (std::size_t k = 0; k < n; ++k) counts[k] = bonds.rows.count[order[k]];
  b.rows = RowIndex::packed(counts);
  b.fit_arena();
  b.live = b.rows.arena;
  std::vector<std::pair<std::int32_t, std::int64_t>> row;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(order[k]);
    row.clear();
    for (auto e = bonds.begin(i); e < bonds.end(i); ++e)
      row.emplace_back(new_index[static_cast<std::size_t>(bonds.neighbor[e])], e);
    std::sort(row.begin(), row.end());
    auto s = static_cast<std::size_t>(b.begin(k));
    for (const auto& [j, e] : row) {
      b.owner[s] = static_cast<std::int32_t>(k);
      b.neighbor[s] = j;
      b.length[s] = bonds.length[e];
      b.weight[s] = bonds.weight[e];
      b.stiffness[s] = bonds.stiffness[e];
      b.intact[s++] = bonds.intact[e];
    }
  }
  return b;
}

namespace {
template <class T>
std::size_t held(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
}  // namespace

std::size_t BondList::bytes() const {
  return rows.bytes() + held(owner) + held(neighbor) + held(length) + held(weight) + held(intact) +
         held(stiffness);
}

std::size_t DualList::bytes() const {
  return rows.bytes() + held(bond);
}

}  // namespace dhpd
