// The refiner: triggers + buffer + grading + level limit pick the parents of an event, which the
// Simulation then applies (docs/theory.md §13.2; IJNME 2016 §5.3).
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/simulation.hpp"
#include "geometry/shapes.hpp"
#include "refine/event.hpp"
#include "refine/settled.hpp"
#include "refine/triggers.hpp"

namespace dhpd::refine {

/// The triggers of a scene that names none (docs/scenes.md, `effects.refinement`): cracks
/// (φ ≥ 0.05) and bonds at 0.8 of their critical stretch anywhere, checked every 2 steps, so a
/// notch tip, a hole's rim or a spall plane is refined while its bonds are still intact and before
/// the coarse lattice's response departs from the fine one (docs/verification.md: at 0.5 checked
/// every 10 steps Kalthoff–Winkler 2D refined half the plate and still cracked where the fine run
/// does not; the four AdaptiveVsFine studies meet their criteria in 4 / 3 / 4 / 4 of 4 runs).
inline Triggers default_triggers() {
  Triggers t;
  t.damage = 0.05;
  t.stretch = 0.8;
  return t;
}

struct Settings {
  Triggers trigger;
  double buffer = 1.0;  ///< particles within buffer × δ_t of a triggered particle t split too
  int max_level = 1;    ///< a particle at this level is never split again
  std::int64_t check_every = 2;        ///< steps of the finest level between checks
  std::vector<geometry::Shape> zones;  ///< refined at start, up to max_level
  /// Where triggers may split particles (empty: everywhere). A triggered or buffered particle
  /// outside every one of them stays; grading still splits what a level jump needs.
  std::vector<geometry::Shape> within;
  StateMapping mapping = StateMapping::Linear;
};

/// Clears the marks of particles outside every shape of `within` (none when it is empty).
void keep_within(const ParticleStore& p, const std::vector<geometry::Shape>& within,
                 std::vector<std::uint8_t>& marked);

/// Adds to `marked` every particle within buffer × δ_t (reference positions) of a marked t not
/// flagged in `skip` (settled: all it would add is at max_level). `grid`: a current search over
/// the particles (the refiner's), else a k-d tree is built.
void add_buffer(const ParticleStore& p, double buffer, std::vector<std::uint8_t>& marked,
                const SpatialGrid* grid = nullptr, const std::vector<std::uint8_t>* skip = nullptr);

/// The parents of an event: the marked particles below max_level, plus, repeatedly, every
/// particle two or more levels coarser than a parent's children within bond reach of them
/// (max(δ_i, δ_q) + Δx_i). After the event no particle is bonded to one more than one level finer
/// or coarser, provided that held before. Sorted ascending.
std::vector<std::int32_t> graded_parents(const Simulation& sim, std::vector<std::uint8_t> marked,
                                         int max_level, const SpatialGrid* grid = nullptr);

class Refiner {
 public:
  explicit Refiner(Settings s) : s_(std::move(s)), settled_(s_.buffer, s_.max_level) {}
  const Settings& settings() const { return s_; }

  /// Called with the parents of each event before it is applied: the caller may log a large
  /// event or refuse one that would exceed its memory budget (by throwing).
  using EventCheck = std::function<void(const Simulation& sim, std::size_t parents)>;
  void set_event_check(EventCheck check) { event_check_ = std::move(check); }
  /// Asked during each event (see split): true stops it with EventCancelled.
  void set_cancel_check(CancelCheck cancelled) { cancelled_ = std::move(cancelled); }
  /// Builds the search the events keep up to date (else the first event builds it).
  void prepare(const Simulation& sim) { search_.grid(sim); }
  /// Splits the zones' particles, level by level up to max_level; one event per level.
  std::vector<RefinementEvent> refine_zones(Simulation& sim);
  /// Whether the refiner checks after `step` (steps counted from 1). With `levels` time levels
  /// the period counts steps of the finest level, check_every / 2^(levels − 1) coarse steps (at
  /// least 1), so the checks come as often in time as with one step at the finest level's
  /// (docs/theory.md §19.3).
  bool due(std::int64_t step, int levels = 1) const {
    const auto period = std::max<std::int64_t>(1, s_.check_every >> std::clamp(levels - 1, 0, 62));
    return s_.trigger.any() && step % period == 0;
  }
  /// due() with the time levels `sim` steps at now.
  bool due(std::int64_t step, const Simulation& sim) const {
    return due(step, sim.time_levels() ? sim.time_levels()->count() : 1);
  }
  /// Triggers, buffer and grading; applies the event when there are parents (parents == 0 in
  /// the returned event otherwise).
  RefinementEvent check(Simulation& sim);

 private:
  /// Whether `sim` is the simulation and discretisation the settled particles were last brought
  /// up to date in (a guard's rollback, or another simulation, starts them afresh).
  bool settled_current(const Simulation& sim) const;
  void mark_settled_current(const Simulation& sim);
  /// The key of this refiner's stretch limits (Simulation::watch_stretch).
  std::uint64_t watch_key() const;
  /// The stepper's stretch hits when the trigger has a stretch threshold and they are current.
  const std::vector<std::uint8_t>* stretch_hits(const Simulation& sim) const;
  /// Gives the stepper the stretch trigger's limits when it holds none.
  void watch_stretch(Simulation& sim) const;

  Settings s_;
  EventSearch search_;  ///< the incremental grid kept between events
  SettledParticles settled_;
  /// Where settled_ was last brought up to date: simulation, generation, particle count.
  const Simulation* settled_sim_ = nullptr;
  std::int64_t settled_generation_ = -1;
  std::size_t settled_particles_ = 0;
  EventCheck event_check_;
  CancelCheck cancelled_;
};

}  // namespace dhpd::refine
