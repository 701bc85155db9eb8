// Time levels of multi-rate stepping (docs/theory.md §19): which particles step at dt₀/2^ℓ, and
// the row segments, drift lists and force arrays of each level.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"

namespace dhpd {

/// What the levels are chosen from (docs/theory.md §19.1).
struct LevelInputs {
  const std::vector<double>& particle_dt;  ///< per-particle stable-step bound (§9.1)
  double critical_dt;                      ///< the run's tight stable step (§9.3)
  double safety;                           ///< time.safety
  std::optional<double> fixed_dt;          ///< time.dt, when the scene fixes it
  int max_levels;                          ///< levels allowed (time.max_levels)
  /// time.multirate left to its default: one global step when the levels would not pay, or when
  /// more than max_levels would be needed (instead of TimeLevelError).
  bool automatic = false;
};

/// The cost of a row-entry evaluation in a level's segment pass relative to one in the global
/// step's pass (measured 1.06 on kalthoff_winkler_2d_fine_coarse.yaml, with a margin;
/// docs/theory.md §19.5): by default levels are used only when they evaluate fewer entries by more
/// than this.
inline constexpr double kLevelOverhead = 1.15;

/// The level of each particle and the coarse step dt₀.
struct LevelChoice {
  std::vector<std::int8_t> level;  ///< per particle
  double dt0 = 0.0;
  double coarse_dt = 0.0;  ///< the stable step of the coarsest particles (dt0 may not exceed it)
  int count = 1;           ///< levels in use: 1 + the largest level
};

/// ℓ_i = max(spacing level, stable-step level), then raised to the largest level of any particle
/// it shares a bond with (a one-horizon buffer around each finer level). dt₀ is the fixed dt when
/// given (the caller refuses one above coarse_dt), else safety × coarse_dt. Throws TimeLevelError
/// when the particles need more than `max_levels` levels. With `automatic`, one level (dt₀ the
/// global step) instead when the levels do not pay (docs/theory.md §19.5) or are too many.
LevelChoice choose_time_levels(const BondRows& rows, const ParticleStore& p, const LevelInputs& in);

/// The order that sorts particles by level, Morton order `morton` kept within a level
/// (order[k]: the particle that goes to slot k).
std::vector<std::int32_t> order_by_level(const std::vector<std::int32_t>& morton,
                                         const std::vector<std::int8_t>& level);

/// An order that sorts particles by level and moves as few as possible (order[k]: the particle
/// that goes to slot k). Slot k stays where level[k] is the level of the block it falls in; the
/// particles of level ℓ outside its block take the block's other slots, both in increasing index.
/// A re-levelling after an event moves the particles that changed level and as many at the block
/// edges, instead of renumbering the body (docs/theory.md §19.3).
std::vector<std::int32_t> fewest_moves_by_level(const std::vector<std::int8_t>& level);

/// One level's share of the bond rows and of the integration (particles sorted by level).
struct LevelPlan {
  std::vector<std::int32_t> rows;   ///< rows with a non-empty segment at this level, ascending
  std::vector<std::int64_t> start;  ///< per particle: the segment's first entry
  std::vector<std::int32_t> count;  ///< per particle: the segment's length (0: none)
  std::vector<std::int32_t> drift;  ///< particles whose finest pair is at this level
  VectorArray force;                ///< F_ℓ per particle (first dim axes)
  std::int64_t own_bonds = 0;       ///< own bonds in the segments (evaluated per pass)
};

/// Every level's plan.
struct TimeLevels {
  std::vector<std::int8_t> level;   ///< per particle, ascending
  std::vector<std::int64_t> first;  ///< first particle of each level, and the count at the end
  std::vector<LevelPlan> plans;
  double dt0 = 0.0, coarse_dt = 0.0;
  int count() const { return static_cast<int>(plans.size()); }
  double dt(int l) const { return dt0 / static_cast<double>(std::int64_t{1} << l); }
  /// Bytes held by the plans (capacities).
  std::size_t bytes() const;
};

/// The plans of `choice` for rows whose particles are sorted by level (throws EngineError
/// otherwise). A pair is integrated at the finer level of its two ends: row i's segment at level
/// ℓ holds the entries whose pair level is ℓ (rows are sorted by neighbour, so it is contiguous).
TimeLevels plan_time_levels(const BondRows& rows, const ParticleStore& p, LevelChoice choice);

}  // namespace dhpd
