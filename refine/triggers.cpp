// Refinement triggers (docs/theory.md §13.1; IJNME 2016 §5.3 refines where damage or energy is
// high).
#include "refine/triggers.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "engine/base/parallel.hpp"
#include "engine/discretization/neighbor_search.hpp"
#include "engine/physics/bond_law.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd::refine {

std::vector<double> critical_energy_density(const Simulation& sim) {
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  std::vector<double> out(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double s0 = sim.critical_stretch()[i];
    if (!std::isfinite(s0)) {
      out[i] = HUGE_VAL;
      continue;
    }
    double w = 0.0;
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      const double length = b.length(k);
      w += bond_law::energy_share(1.0, length,
                                  bond_weight(p, sim.setup().partial_volume, i, j, length),
                                  b.own_factor(k), p.volume[j]);
    });
    out[i] = 0.5 * sim.micromodulus()[i] * s0 * s0 * w;
  }
  return out;
}

namespace {

/// Each row's largest (|y|/|ξ|)² over its intact own bonds (0 without one, or when `skip` flags
/// it): squared lengths times 1/|ξ|², as the break test forms them, no root or division per bond.
/// Each row is its own maximum: the same for any team.
template <int Dim>
void max_ratio2_rows(const Simulation& sim, const std::vector<std::uint8_t>* skip,
                     std::vector<double>& out) {
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  const double* const y[3] = {p.position[0].data(), p.position[1].data(), p.position[2].data()};
  const auto n = static_cast<std::int64_t>(p.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    const auto row = static_cast<std::size_t>(i);
    double largest = 0.0;
    if (skip && (*skip)[row]) {
      out[row] = largest;
      continue;
    }
    for (auto k = b.begin(row); k < b.end(row); ++k) {
      if (!b.own_intact(k)) continue;
      const auto j = static_cast<std::size_t>(b.other[k]);
      const double l2 = bond_law::squared_length<Dim>(y, row, j);
      largest = std::max(largest, bond_law::stretch_ratio2(l2, b.inverse_length(k)));
    }
    out[row] = largest;
  }
}

std::vector<double> max_ratio2(const Simulation& sim,
                               const std::vector<std::uint8_t>* skip = nullptr) {
  std::vector<double> out(sim.particles().size(), 0.0);
  switch (sim.particles().dim()) {
    case 1:
      max_ratio2_rows<1>(sim, skip, out);
      break;
    case 2:
      max_ratio2_rows<2>(sim, skip, out);
      break;
    default:
      max_ratio2_rows<3>(sim, skip, out);
      break;
  }
  return out;
}

}  // namespace

std::vector<double> max_bond_stretch(const Simulation& sim) {
  auto out = max_ratio2(sim);
  for (auto& r : out) r = r > 0.0 ? std::sqrt(r) - 1.0 : 0.0;
  return out;
}

std::vector<std::uint8_t> near_a_crack(const Simulation& sim, CrackReach reach_horizons,
                                       std::vector<std::uint8_t> asked) {
  const double horizons = reach_horizons.running;
  const auto& p = sim.particles();
  const int dim = p.dim();
  const auto& body = sim.setup().body;
  double step = HUGE_VAL;
  for (const double h : p.spacing) step = std::min(step, 0.25 * h);
  std::vector<geometry::CrackFront> fronts;
  for (const auto& c : sim.setup().cracks) {
    const auto f = geometry::crack_fronts(
        c, dim, step, [&](const geometry::Vec3& x) { return !body || body->contains(x, dim); });
    fronts.insert(fronts.end(), f.begin(), f.end());
  }
  // The damaged particles, searched around each asked particle's position (the tree is built
  // when some asked particle is not near a pre-crack's front).
  VectorArray points;
  std::vector<double> damaged_horizon;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.damage[i] >= kFrontDamage) {
      for (int a = 0; a < 3; ++a) points[a].push_back(p.reference_position[a][i]);
      damaged_horizon.push_back(p.horizon[i]);
    }
  const double widest = damaged_horizon.empty()
                            ? 0.0
                            : *std::max_element(damaged_horizon.begin(), damaged_horizon.end());
  auto& out = asked;
  std::unique_ptr<NeighborSearch> search;
  std::vector<std::int32_t> found;
  const auto near_damage = [&](std::size_t i) {
    if (!search) search = std::make_unique<NeighborSearch>(points, dim);
    // A running crack's reach is counted in the damaged particle's own horizon: a refined tip
    // (δ/2) pulls in a band half as wide as a coarse one would (docs/theory.md §13.1).
    const double x[3] = {p.reference_position[0][i], p.reference_position[1][i],
                         p.reference_position[2][i]};
    search->around(x, horizons * widest, found);
    for (const auto j : found) {
      const auto uj = static_cast<std::size_t>(j);
      double d2 = 0.0;
      for (int a = 0; a < dim; ++a) {
        const double d = points[a][uj] - x[a];
        d2 += d * d;
      }
      const double reach = horizons * damaged_horizon[uj];
      if (d2 <= reach * reach) return true;
    }
    return false;
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!out[i]) continue;
    const double reach = reach_horizons.precrack * p.horizon[i];
    const auto x = point_of(p.reference_position, i);
    bool near = false;
    for (const auto& f : fronts) near = near || geometry::distance_to(f, x) <= reach;
    if (!near && !damaged_horizon.empty()) near = near_damage(i);
    out[i] = near ? 1 : 0;
  }
  return out;
}

double stretch_threshold(double stretch, int level, int max_level) {
  return std::pow(stretch, std::max(1, max_level - level));
}

std::vector<double> stretch_limits(const Simulation& sim, double stretch, int max_level) {
  const auto& level = sim.particles().level;
  std::vector<double> out(level.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = bond_law::critical_ratio2(stretch_threshold(stretch, level[i], max_level) *
                                       sim.critical_stretch()[i]);
  return out;
}

std::vector<std::uint8_t> triggered(const Simulation& sim, const Triggers& t,
                                    const TriggerScope& scope) {
  const std::size_t n = sim.particles().size();
  std::vector<std::uint8_t> out(n, 0);
  if (t.damage) {  // damage is current: the stepper refreshes it where bonds break
    for (std::size_t i = 0; i < n; ++i)
      if (sim.particles().damage[i] >= *t.damage) out[i] = 1;
  }
  if (t.energy) {
    std::vector<double> w;
    strain_energy_density(sim.bonds(), sim.bond_constants(), w);
    const auto crit = critical_energy_density(sim);
    for (std::size_t i = 0; i < n; ++i)
      if (crit[i] > 0.0 && w[i] >= *t.energy * crit[i]) out[i] = 1;
  }
  if (t.stretch) {
    std::vector<std::uint8_t> over(n, 0);
    if (const auto* hits = scope.stretch_hits) {  // the last step's force passes watched
      for (std::size_t i = 0; i < n; ++i)
        over[i] = !out[i] && (*hits)[i] && !(scope.skip && (*scope.skip)[i]) ? 1 : 0;
    } else {
      // s ≥ t·s0 compared on squared ratios: (|y|/|ξ|)² ≥ (1 + t·s0)².
      const auto ratio2 = max_ratio2(sim, scope.skip);
      const auto limit = stretch_limits(sim, *t.stretch, scope.max_level);
      for (std::size_t i = 0; i < n; ++i)
        over[i] = !out[i] && ratio2[i] > 0.0 && ratio2[i] >= limit[i] ? 1 : 0;
    }
    if (t.near_crack)
      over = near_a_crack(sim, {*t.near_crack, t.near_precrack.value_or(*t.near_crack)},
                          std::move(over));
    for (std::size_t i = 0; i < n; ++i) out[i] = out[i] || over[i];
  }
  return out;
}

}  // namespace dhpd::refine
