// Pair stiffness and break thresholds of the bond rows (IJNME 2016 eq. 27; CMAME 2017 §3, eq. 5;
// docs/theory.md §4, §18).
#include "engine/physics/interactions.hpp"

#include <algorithm>
#include <limits>

#include "engine/base/parallel.hpp"
#include "engine/physics/multi_horizon.hpp"

namespace dhpd {

double bond_stiffness(const BondConstants& c, std::size_t owner, std::size_t neighbor,
                      double length, double factor) {
  // Classical BB-PD: 2C on each own bond, no reactions (IJNME 2016 §3.1).
  const double model_factor = c.model == ForceModel::DualHorizon ? 1.0 : 2.0;
  const double beta = bond_weight(c.particles, c.rule, owner, neighbor, length);
  return model_factor * c.micromodulus[owner] * beta * factor;
}

double dual_bond_stiffness(const BondRows& b, const BondConstants& c, std::size_t i,
                           std::int64_t k) {
  const auto j = static_cast<std::size_t>(b.other[k]);
  // φ of j's bond lives in row j (constant between edits, so any thread may read it).
  const double factor =
      b.factor.empty() ? 1.0 : b.own_factor(b.find(j, static_cast<std::int32_t>(i)));
  return bond_stiffness(c, j, i, b.length(k), factor);
}

float entry_stiffness(const BondRows& b, const BondConstants& c, std::size_t i, std::int64_t k) {
  if (c.model == ForceModel::MultiHorizon)
    return static_cast<float>(
        multi_horizon_stiffness(b, c.particles, c.rule, c.micromodulus, c.interaction_scale, i, k) /
        b.stiffness_scale);
  const auto f = b.flags[k];
  double K = 0.0;
  if (f & kOwnIntact)
    K += bond_stiffness(c, i, static_cast<std::size_t>(b.other[k]), b.length(k), b.own_factor(k));
  // The dual bond's term, added second: row j adds the same two terms the other way round, and
  // IEEE addition is commutative, so both rows store the same bits.
  if ((f & kDualIntact) && c.model == ForceModel::DualHorizon) {
    const double dual = dual_bond_stiffness(b, c, i, k);
    K = (f & kOwnIntact) ? K + dual : dual;
  }
  return static_cast<float>(K / b.stiffness_scale);
}

void refresh_row(BondRows& b, const BondConstants& c, std::size_t i) {
  double smallest = std::numeric_limits<double>::infinity();
  const bool own_breaks = c.can_break(i);
  for (auto k = b.begin(i); k < b.end(i); ++k) {
    b.stiffness[k] = entry_stiffness(b, c, i, k);
    if ((b.flags[k] & kOwn) && own_breaks) smallest = std::min(smallest, c.break_ratio2(i));
    const auto j = static_cast<std::size_t>(b.other[k]);
    if ((b.flags[k] & kDual) && c.can_break(j)) smallest = std::min(smallest, c.break_ratio2(j));
  }
  b.break_ratio2[i] = smallest;
}

double stiffness_scale_for(const std::vector<double>& micromodulus) {
  double largest = 0.0;
  for (const double C : micromodulus)
    if (std::isfinite(C)) largest = std::max(largest, C);
  return largest > 0.0 ? std::ldexp(1.0, std::ilogb(largest)) : 1.0;
}

void refresh_rows(BondRows& b, const BondConstants& c, bool choose_scale) {
  if (choose_scale) b.stiffness_scale = stiffness_scale_for(c.micromodulus);
  b.break_ratio2.resize(b.particles());
  const auto n = static_cast<std::int64_t>(b.particles());
#pragma omp parallel for schedule(dynamic, 256) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) refresh_row(b, c, static_cast<std::size_t>(i));
}

int break_entry(BondRows& b, std::size_t i, std::int64_t k, double ratio2, const BondConstants& c) {
  const auto j = static_cast<std::size_t>(b.other[k]);
  auto f = b.flags[k];
  int broken = 0;
  if ((f & kOwnIntact) && c.can_break(i) && ratio2 >= c.break_ratio2(i)) {
    f = static_cast<std::uint8_t>(f & ~kOwnIntact);
    broken = 1;
  }
  if ((f & kDualIntact) && c.can_break(j) && ratio2 >= c.break_ratio2(j))
    f = static_cast<std::uint8_t>(f & ~kDualIntact);
  if (f != b.flags[k]) {
    b.flags[k] = f;
    b.stiffness[k] = entry_stiffness(b, c, i, k);
  }
  return broken;
}

}  // namespace dhpd
