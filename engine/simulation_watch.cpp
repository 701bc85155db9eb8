// The stretch watch of the stepper (docs/theory.md §13.1): the refinement's stretch trigger read
// from the break test of each step's force passes instead of a pass of its own over every bond.
#include <algorithm>

#include "engine/base/errors.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

void Simulation::watch_stretch(std::vector<double> limit_ratio2, std::uint64_t key) {
  if (limit_ratio2.size() != p_.size())
    throw EngineError("watch_stretch: one limit per particle is needed");
  watch_.limit = std::move(limit_ratio2);
  watch_.key = key;
  watch_.hit.assign(p_.size(), 0);
  watch_.level_hit.clear();
  watch_.current = false;
}

kernel::StretchWatch Simulation::stretch_watch_into(std::vector<std::uint8_t>& hits) {
  if (!watch_fits()) return {};
  hits.resize(p_.size(), 0);
  return {watch_.limit.data(), hits.data()};
}

kernel::StretchWatch Simulation::level_stretch_watch(int level) {
  if (!watch_fits()) return {};
  const auto n = p_.size();
  watch_.level_hit.resize(n * static_cast<std::size_t>(levels_->count()), 0);
  return {watch_.limit.data(), watch_.level_hit.data() + n * static_cast<std::size_t>(level)};
}

void Simulation::merge_level_watch() {
  // A row's segment at each level was last evaluated at the end of the dt₀ step (§19.2); rows
  // without a segment at a level keep the 0 they were given with the plans.
  const auto n = p_.size();
  watch_.hit.assign(n, 0);
  if (watch_.level_hit.size() != n * static_cast<std::size_t>(levels_->count())) return;
  for (int l = 0; l < levels_->count(); ++l) {
    const std::uint8_t* level = watch_.level_hit.data() + n * static_cast<std::size_t>(l);
    for (std::size_t i = 0; i < n; ++i) watch_.hit[i] |= level[i];
  }
}

}  // namespace dhpd
