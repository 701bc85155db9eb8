// Refinement triggers (dhpd.md §8; IJNME 2016 §5.3 refines where damage or energy is high).
#include "refine/triggers.hpp"

#include <algorithm>
#include <cmath>

#include "engine/kernels.hpp"

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
    for (auto k = b.begin(i); k < b.end(i); ++k)
      w += b.length[k] * b.weight[k] * p.volume[static_cast<std::size_t>(b.neighbor[k])];
    out[i] = 0.5 * sim.micromodulus()[i] * s0 * s0 * w;
  }
  return out;
}

std::vector<double> max_bond_stretch(const Simulation& sim) {
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  std::vector<double> out(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      if (!b.intact[k]) continue;
      const auto j = static_cast<std::size_t>(b.neighbor[k]);
      out[i] = std::max(out[i], current_stretch(p, i, j, b.length[k]));
    }
  return out;
}

std::vector<std::uint8_t> triggered(Simulation& sim, const Triggers& t) {
  const std::size_t n = sim.particles().size();
  std::vector<std::uint8_t> out(n, 0);
  if (t.damage) {
    sim.update_damage();
    for (std::size_t i = 0; i < n; ++i)
      if (sim.particles().damage[i] >= *t.damage) out[i] = 1;
  }
  if (t.energy) {
    std::vector<double> w;
    strain_energy_density(sim.bonds(), sim.particles(), sim.micromodulus(), w);
    const auto crit = critical_energy_density(sim);
    for (std::size_t i = 0; i < n; ++i)
      if (crit[i] > 0.0 && w[i] >= *t.energy * crit[i]) out[i] = 1;
  }
  if (t.stretch) {
    const auto s = max_bond_stretch(sim);
    for (std::size_t i = 0; i < n; ++i)
      if (s[i] >= *t.stretch * sim.critical_stretch()[i]) out[i] = 1;
  }
  return out;
}

}  // namespace dhpd::refine
