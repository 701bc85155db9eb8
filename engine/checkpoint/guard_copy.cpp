// The guard's copy of a simulation (see guard_copy.hpp).
#include "engine/checkpoint/guard_copy.hpp"

#include <stdexcept>

#include "engine/checkpoint/archive.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/checkpoint/checkpoint_access.hpp"

namespace dhpd {

void save_step_state_into(const Simulation& sim, std::vector<std::byte>& out) {
  CheckpointAccess::save_into(
      sim, out, [](const Simulation& s, auto& ar) { CheckpointAccess::save_step(s, ar); });
}

void load_step_state(const std::vector<std::byte>& bytes, Simulation& sim,
                     const std::vector<std::int64_t>* saved_start) {
  archive::Reader r(bytes, "the guard's copy");
  CheckpointAccess::load_step(sim, r, saved_start);
}

void GuardCopy::take(const Simulation& sim) {
  save_step_state_into(sim, step_);
  std::vector<std::byte>().swap(whole_);
  std::vector<std::int64_t>().swap(row_start_);
  generation_ = sim.generation();
  layout_ = sim.layout_version();
}

void GuardCopy::before_edit(const Simulation& sim) {
  if (step_.empty() || !whole_.empty()) return;
  if (!same_discretisation(sim))
    throw std::logic_error("GuardCopy::before_edit: the discretisation changed since take()");
  save_simulation_into(sim, whole_);
  // The whole state is saved with its rows packed; the step part has the flags as the arena
  // holds them now, with room between rows after events: restore() packs them by these starts.
  row_start_ = sim.bonds().rows.start;
}

void GuardCopy::restore(Simulation& sim) const {
  if (step_.empty()) throw std::logic_error("GuardCopy::restore: nothing was taken");
  if (!whole_.empty()) {
    load_simulation(whole_, sim, "the guard's copy");
    load_step_state(step_, sim, &row_start_);
    return;
  }
  if (!same_discretisation(sim))
    throw std::logic_error(
        "GuardCopy::restore: the discretisation changed after take() without before_edit()");
  load_step_state(step_, sim);
}

}  // namespace dhpd
