// Settled particles: at max_level with every particle within buffer × δ at max_level too. Nothing
// such a particle marks can split (graded_parents drops marks at max_level), so the refiner skips
// its triggers and its buffer search, with the same parents as without (docs/theory.md §13.2).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "refine/spatial_grid.hpp"

namespace dhpd::refine {

class SettledParticles {
 public:
  SettledParticles(double buffer, int max_level) : buffer_(buffer), max_level_(max_level) {}

  /// Examines the particles at max_level not examined since they were born or last unsettled,
  /// then returns, per current index, 1 where settled. Kept by particle id: renumberings keep it.
  const std::vector<std::uint8_t>& update(const ParticleStore& p, const SpatialGrid& grid);

  /// After an event whose children have ids ≥ first_new_id: every particle within reach of a
  /// child (buffer × the largest horizon at max_level, plus the child's spacing) is examined
  /// again, settled or not, since a child below max_level unsettles it and a split coarse
  /// neighbour may settle it.
  void after_event(const ParticleStore& p, const SpatialGrid& grid, std::int32_t first_new_id);

  /// Forgets every particle (after an event without the search, e.g. refinement zones).
  void clear() { state_.clear(); }

 private:
  enum : std::uint8_t { kUnknown = 0, kSettled = 1, kOpen = 2 };
  std::uint8_t& state_of(std::int32_t id);
  bool examine(const ParticleStore& p, const SpatialGrid& grid, std::size_t i);

  double buffer_;
  int max_level_;
  std::vector<std::uint8_t> state_;  ///< by particle id
  std::vector<std::uint8_t> mask_;   ///< by current index
  std::vector<std::int32_t> near_;
};

}  // namespace dhpd::refine
