// The instability guard's copy of a simulation (docs/checkpoint.md, "The guard's copy"): the
// newest state that passed the guard, kept so an unstable or stopped run can still write it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "engine/simulation.hpp"

namespace dhpd {

/// Between edits a time step changes only particle fields, bond states and a few scalars, so
/// take() copies just those (on the default plate about a sixth of the whole state). The whole
/// state is copied only when the discretisation is about to change while a copy is held
/// (before_edit): restore() then loads it and overlays the step part. Without an edit since
/// take(), restore() overlays the step part on the current bonds and rows. Either way the
/// restored simulation continues bit for bit like the one copied (test: GuardCopy).
class GuardCopy {
 public:
  /// Replaces the copy with the current state (releases a whole-state copy).
  void take(const Simulation& sim);
  /// Call before anything edits the discretisation (a refinement event, a compaction): keeps the
  /// bonds and rows the step part belongs to, unless that was done since take().
  void before_edit(const Simulation& sim);
  /// Puts the copied state back into `sim` (built from the same setup). Throws std::logic_error
  /// when the discretisation changed without before_edit.
  void restore(Simulation& sim) const;
  bool empty() const { return step_.empty(); }
  /// The bytes held now: the step part, and the whole state after before_edit.
  std::size_t bytes() const {
    return step_.capacity() + whole_.capacity() + row_start_.capacity() * sizeof(std::int64_t);
  }
  /// Whether the whole state is held (an edit came after take()).
  bool holds_whole_state() const { return !whole_.empty(); }

 private:
  bool same_discretisation(const Simulation& sim) const {
    return sim.generation() == generation_ && sim.layout_version() == layout_;
  }
  std::vector<std::byte> step_, whole_;
  std::vector<std::int64_t> row_start_;  ///< the rows' starts at before_edit (see restore)
  std::int64_t generation_ = -1, layout_ = -1;
};

/// The step part alone (what GuardCopy::take keeps), and its overlay on a simulation of the same
/// discretisation: throws InputError when the bytes do not fit it.
void save_step_state_into(const Simulation& sim, std::vector<std::byte>& out);
/// `saved_start`: the row starts the step part was saved with, when `sim` holds its rows packed.
void load_step_state(const std::vector<std::byte>& bytes, Simulation& sim,
                     const std::vector<std::int64_t>* saved_start = nullptr);

}  // namespace dhpd
