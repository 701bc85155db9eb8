// The incremental rebuild of a refinement event (docs/theory.md; IJNME 2016 §5.3): which bond
// rows an event rewrites, and rewriting them against the previous generation (no healing).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "refine/split_plan.hpp"

namespace dhpd::refine {

/// One event between its phases (event.cpp and rebuild.cpp only).
struct EventScratch {
  SplitPlan plan;
  ParticleStore parents;             ///< the parents' fields before the split
  std::vector<std::int32_t> near;    ///< previous-generation owners near the parents (rule b)
  std::vector<std::int32_t> owners;  ///< bond rows rebuilt, ascending
  std::vector<std::int32_t> dirty;   ///< bond rows rewritten (own or dual side), ascending
  std::int64_t broken_change = 0;    ///< broken bonds after minus before
  std::vector<std::int32_t>* parent_slot = nullptr;    ///< per slot: index into plan.parents
  std::vector<std::int32_t>* child_of_slot = nullptr;  ///< per slot: index of its child
};

/// Owners of the previous generation whose old bonds may cross a new bond (no-healing rule b).
std::vector<std::int32_t> old_neighbourhood(const Simulation& sim, const SpatialGrid& grid,
                                            const SplitPlan& plan,
                                            const CancelCheck& cancelled = {});
/// Rows whose energy the event can change (for the energy ledger), ascending.
std::vector<std::int32_t> event_energy_rows(const Simulation& sim, const SpatialGrid& grid,
                                            const SplitPlan& plan,
                                            const CancelCheck& cancelled = {});
/// Owners whose rows are rebuilt: the children, the owners of bonds on the parents and the
/// unsplit particles whose horizon reaches a child; ascending.
std::vector<std::int32_t> owners_to_rebuild(const Simulation& sim, const SpatialGrid& grid,
                                            const EventScratch& ev,
                                            const CancelCheck& cancelled = {});
/// Decides the owners' new own bonds against the previous generation and puts them in place of
/// the old ones, own side and dual side (ev.dirty: every row that changed).
/// These searches ask `cancelled` every 256 items (EventCancelled; see split).
void rebuild_rows(const Simulation& sim, Simulation::Discretisation d, const SpatialGrid& grid,
                  EventScratch& ev, RefinementEvent& out, const CancelCheck& cancelled);

}  // namespace dhpd::refine
