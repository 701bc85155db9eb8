// One refinement event (IJNME 2016 §5.3; docs/theory.md §13): split the parents into children with
// mapped state, rebuild the touched bond rows incrementally under the no-healing rule, and hand
// the change to the engine through its edit seam.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/spatial_grid.hpp"
#include "refine/state_mapping.hpp"

namespace dhpd::refine {

/// What one refinement event did.
/// Whether an event should stop now (e.g. SIGTERM arrived); empty: never.
using CancelCheck = std::function<bool()>;

/// An event stopped part way by its CancelCheck.
class EventCancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Asks `cancelled` every 256th call (the loops of an event call it once per item).
class CancelPoll {
 public:
  explicit CancelPoll(const CancelCheck& cancelled) : cancelled_(cancelled) {}
  void operator()(const char* where) {
    if (cancelled_ && ++calls_ % 256 == 0 && cancelled_())
      throw EventCancelled(std::string("refinement event cancelled while ") + where);
  }

 private:
  const CancelCheck& cancelled_;
  std::size_t calls_ = 0;
};

struct RefinementEvent {
  std::int64_t generation = 0;  ///< the generation the event created
  std::size_t parents = 0, children = 0;
  std::size_t dropped = 0;          ///< children not created (outside the body)
  std::size_t rows_rebuilt = 0;     ///< owners whose bond rows were rebuilt
  std::size_t bonds_rebuilt = 0;    ///< bonds written by the event
  std::size_t rows_touched = 0;     ///< bond rows rewritten (owners and their neighbours)
  std::size_t bonds = 0;            ///< bonds after the event
  std::int64_t started_broken = 0;  ///< new bonds set broken by the no-healing rule
  /// New bonds set broken because the mapped state stretched them to s0 (starts_overstretched).
  std::int64_t started_overstretched = 0;
  InterfaceCorrection interfaces;  ///< the stiffness factors the event solved for
  std::size_t reduced_fits = 0;    ///< parents whose mapping gradient had a reduced rank
  double seconds = 0.0;            ///< the event itself (split and incremental rebuild)
  bool resorted = false;           ///< the store was re-sorted and compacted after the event
  double resort_seconds = 0.0;     ///< cost of that re-sort (not in `seconds`)
  double energy_change = 0.0;      ///< kinetic + strain energy the state mapping added (J)
  double shadow_change = 0.0;      ///< the same for the shadow energy (new dt and forces too)
};

/// What refinement keeps between its events: the incremental search grid over reference
/// positions and per-slot scratch, so that an event costs in proportion to what it touches. Not
/// part of any checkpoint: it is rebuilt from the particles whenever the simulation is not the
/// one, or not at the generation and layout, it was last brought up to date for.
class EventSearch {
 public:
  SpatialGrid& grid(const Simulation& sim);
  /// Marks the grid as matching `sim` now (after an event updated it incrementally).
  void mark_current(const Simulation& sim);
  std::vector<std::int32_t> parent_slot, child_of_slot;  ///< −1 outside events

 private:
  std::optional<SpatialGrid> grid_;
  const Simulation* sim_ = nullptr;
  std::int64_t generation_ = -1, layout_ = -1;
};

/// Splits the given particles (indices of the current generation) into up to 2^dim children each
/// (plan_split; u and v by `mapping`) and rebuilds incrementally: only the children and the
/// owners of bonds on the parents or within reach of a child get new own bonds; their
/// neighbours' rows get the dual side; the no-healing rule sets the new bonds;
/// the engine then derives loads, stable step, forces and damage of the touched particles. A
/// parent's first child takes its slot, the other children are appended, so every other index
/// stays valid, unless the event ends with a compaction (RefinementEvent::resorted). Refused for
/// constant-horizon (one δ for the whole body). Without `search` a grid is built for this event.
/// `cancelled` is asked between the phases and every few hundred rebuilt rows; when it answers
/// true the event throws EventCancelled and leaves the simulation half edited: the caller restores
/// a saved state (the run's last good copy) or discards the simulation.
RefinementEvent split(Simulation& sim, const std::vector<std::int32_t>& parents,
                      StateMapping mapping = StateMapping::Linear, EventSearch* search = nullptr,
                      const CancelCheck& cancelled = {});

}  // namespace dhpd::refine
