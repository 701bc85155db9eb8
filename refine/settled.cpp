// Settled particles (see settled.hpp; docs/theory.md §13.2).
#include "refine/settled.hpp"

#include <algorithm>

namespace dhpd::refine {

std::uint8_t& SettledParticles::state_of(std::int32_t id) {
  const auto k = static_cast<std::size_t>(id);
  if (k >= state_.size())
    state_.resize(std::max(k + 1, state_.size() + state_.size() / 2), kUnknown);
  return state_[k];
}

bool SettledParticles::examine(const ParticleStore& p, const SpatialGrid& grid, std::size_t i) {
  if (buffer_ <= 0.0) return true;
  grid.within(point_of(p.reference_position, i), buffer_ * p.horizon[i], near_,
              static_cast<std::int32_t>(i));
  return std::all_of(near_.begin(), near_.end(), [&](std::int32_t j) {
    return p.level[static_cast<std::size_t>(j)] >= max_level_;
  });
}

const std::vector<std::uint8_t>& SettledParticles::update(const ParticleStore& p,
                                                          const SpatialGrid& grid) {
  mask_.assign(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.level[i] < max_level_) continue;
    auto& s = state_of(p.id[i]);
    if (s == kUnknown) s = examine(p, grid, i) ? kSettled : kOpen;
    mask_[i] = s == kSettled ? 1 : 0;
  }
  return mask_;
}

void SettledParticles::after_event(const ParticleStore& p, const SpatialGrid& grid,
                                   std::int32_t first_new_id) {
  double widest = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.level[i] >= max_level_) widest = std::max(widest, p.horizon[i]);
  for (std::size_t c = 0; c < p.size(); ++c) {
    if (p.id[c] < first_new_id) continue;
    grid.within(point_of(p.reference_position, c), buffer_ * widest + p.spacing[c], near_);
    for (const auto j : near_) state_of(p.id[static_cast<std::size_t>(j)]) = kUnknown;
  }
}

}  // namespace dhpd::refine
