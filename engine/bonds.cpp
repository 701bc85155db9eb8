// Bond and dual-bond construction (dhpd.md §1; §6 = CMAME 2017 eq. A.1 and App. A; §7 pre-cracks).
#include "engine/bonds.hpp"
#include "engine/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/errors.hpp"
#include "engine/neighbor_search.hpp"
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

/// The rule and how far past δ_i a neighbour can still overlap the horizon (r_max for exact).
struct Rule {
  PartialVolume pv;
  double reach;
};

Rule make_rule(const ParticleStore& p, PartialVolume pv) {
  if (pv != PartialVolume::Exact) return {pv, 0.0};
  double r_max = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p.radius[i] > 0.0))
      throw EngineError(
          "partial_volume exact needs every particle radius > 0 (set_particle_radii)");
    r_max = std::max(r_max, p.radius[i]);
  }
  return {pv, r_max};
}

bool crosses_any(const std::vector<geometry::Crack>& cracks, const geometry::Vec3& a,
                 const geometry::Vec3& b, int dim) {
  for (const auto& c : cracks)
    if (geometry::crosses(c, a, b, dim)) return true;
  return false;
}

geometry::Vec3 point(const VectorArray& x, std::size_t i) {
  return {x[0][i], x[1][i], x[2][i]};
}

/// Candidates of owner i that become bonds, with their lengths and weights.
void bonds_of(std::size_t i, const ParticleStore& p, const Rule& rule,
              const std::vector<geometry::Crack>& cracks, const NeighborSearch& search,
              std::vector<std::int32_t>& cand, std::vector<double>* len, std::vector<double>* w) {
  const auto& X = p.reference_position;
  const double delta = p.horizon[i];
  search.within(i, (delta + rule.reach) * (1.0 + 1e-9), cand);
  std::size_t kept = 0;
  const auto xi = point(X, i);
  for (const auto j : cand) {
    double d2 = 0.0;
    for (int a = 0; a < p.dim(); ++a) {
      const double d = X[a][j] - X[a][i];
      d2 += d * d;
    }
    const double dist = std::sqrt(d2);
    const double r_j = rule.pv == PartialVolume::Exact ? p.radius[j] : 0.5 * p.spacing[j];
    const double beta = partial_volume_factor(rule.pv, p.dim(), dist, delta, r_j);
    if (beta <= 0.0 || dist == 0.0) continue;
    if (!cracks.empty() && crosses_any(cracks, xi, point(X, j), p.dim())) continue;
    cand[kept++] = j;
    if (len) len->push_back(dist), w->push_back(beta);
  }
  cand.resize(kept);
}

}  // namespace

BondList build_bonds(const ParticleStore& p, PartialVolume pv,
                     const std::vector<geometry::Crack>& cracks) {
  const std::size_t n = p.size();
  const Rule rule = make_rule(p, pv);
  NeighborSearch search(p.reference_position, p.dim());
  BondList b;
  b.offset.assign(n + 1, 0);
  // Pass 1: count each row (parallel, independent rows).
#pragma omp parallel if (static_cast <std::int64_t>(n) >= kParallelMinParticles)
  {
    std::vector<std::int32_t> cand;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      bonds_of(static_cast<std::size_t>(i), p, rule, cracks, search, cand, nullptr, nullptr);
      b.offset[i + 1] = static_cast<std::int64_t>(cand.size());
    }
  }
  std::partial_sum(b.offset.begin(), b.offset.end(), b.offset.begin());
  const auto nb = static_cast<std::size_t>(b.offset[n]);
  if (nb > static_cast<std::size_t>(INT32_MAX))
    throw EngineError("more than 2^31 bonds: not supported by 32-bit bond ids");
  b.owner.resize(nb);
  b.neighbor.resize(nb);
  b.length.resize(nb);
  b.weight.resize(nb);
  b.intact.assign(nb, 1);
  // Pass 2: fill each row at its offset (same candidates, same order: deterministic).
#pragma omp parallel if (static_cast <std::int64_t>(n) >= kParallelMinParticles)
  {
    std::vector<std::int32_t> cand;
    std::vector<double> len, w;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      len.clear(), w.clear();
      bonds_of(static_cast<std::size_t>(i), p, rule, cracks, search, cand, &len, &w);
      const auto o = static_cast<std::size_t>(b.offset[i]);
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
  DualList d;
  d.offset.assign(n + 1, 0);
  for (const auto j : bonds.neighbor) ++d.offset[static_cast<std::size_t>(j) + 1];
  std::partial_sum(d.offset.begin(), d.offset.end(), d.offset.begin());
  d.bond.resize(bonds.size());
  std::vector<std::int64_t> fill(d.offset.begin(), d.offset.end() - 1);
  for (std::size_t b = 0; b < bonds.size(); ++b)
    d.bond[static_cast<std::size_t>(fill[static_cast<std::size_t>(bonds.neighbor[b])]++)] =
        static_cast<BondId>(b);
  return d;
}

}  // namespace dhpd
