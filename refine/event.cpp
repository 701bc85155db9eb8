// A refinement event through the engine's edit seam (docs/theory.md §13.6; IJNME 2016 §5.3): split,
// rebuild the touched rows incrementally, no healing; the engine derives the rest; and the
// occasional compaction when appended particles or garbage bonds pile up.
#include "refine/event.hpp"

#include <algorithm>
#include <chrono>

#include "engine/base/errors.hpp"
#include "refine/rebuild.hpp"

namespace dhpd::refine {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

SpatialGrid& EventSearch::grid(const Simulation& sim) {
  const bool current =
      grid_ && sim_ == &sim && generation_ == sim.generation() && layout_ == sim.layout_version();
  const auto& moves = sim.last_slot_moves();
  if (!current && grid_ && sim_ == &sim && generation_ == sim.generation() &&
      layout_ + 1 == sim.layout_version() && moves.layout == sim.layout_version()) {
    grid_->move_slots(moves.moved, moves.source);  // a regrouping by level since: follow it
    mark_current(sim);
  } else if (!current) {
    const auto& p = sim.particles();
    double base = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) base = std::max(base, p.spacing[i]);
    grid_.emplace(p.dim(), base, sim.setup().horizon_factor);
    for (std::size_t i = 0; i < p.size(); ++i)
      grid_->insert(static_cast<std::int32_t>(i), point_of(p.reference_position, i), p.spacing[i]);
    mark_current(sim);
  }
  return *grid_;
}

void EventSearch::mark_current(const Simulation& sim) {
  sim_ = &sim;
  generation_ = sim.generation();
  layout_ = sim.layout_version();
}

namespace {

/// Writes the children through the edit seam and puts them in the grid (their first child takes
/// each parent's slot and so replaces it there).
void write_event_children(Simulation& sim, Simulation::Discretisation d, SpatialGrid& grid,
                          EventScratch& ev, StateMapping mapping, RefinementEvent& out,
                          const CancelCheck& cancelled) {
  const auto& plan = ev.plan;
  auto& p = d.particles;
  ev.parents = gather(p, plan.parents);
  std::vector<std::int32_t> held(sim.loads().prescribed);
  std::sort(held.begin(), held.end());
  const auto state = map_state(plan, mapping, p, d.bonds, sim.setup().partial_volume, held,
                               donors_across_cracks(plan, p, sim.setup().cracks, grid));
  out.reduced_fits = state.reduced_fits;
  ev.near = old_neighbourhood(sim, grid, plan, cancelled);
  ev.parent_slot->resize(plan.new_size, -1);
  ev.child_of_slot->resize(plan.new_size, -1);
  for (std::size_t k = 0; k < plan.parents.size(); ++k)
    (*ev.parent_slot)[static_cast<std::size_t>(plan.parents[k])] = static_cast<std::int32_t>(k);
  write_children(p, plan, ev.parents, state, sim.setup().section,
                 sim.take_ids(plan.child_slot.size()));
  for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
    const auto s = plan.child_slot[c];
    (*ev.child_of_slot)[static_cast<std::size_t>(s)] = static_cast<std::int32_t>(c);
    grid.insert(s, plan.child_position[c], p.spacing[static_cast<std::size_t>(s)]);
  }
  sim.particles_written(plan.child_slot);
}

/// The change the engine derives from: every child is new and takes over its parent's loads.
DiscretisationChange change_of(const EventScratch& ev) {
  DiscretisationChange c;
  c.new_particles = ev.plan.child_slot;
  c.rewritten_rows = ev.owners;
  c.changed_rows = ev.dirty;
  c.successor = ev.plan.child_slot;
  for (const auto k : ev.plan.child_parent) c.predecessor.push_back(ev.plan.parents[k]);
  c.old_size = ev.plan.old_size;
  return c;
}

}  // namespace

RefinementEvent split(Simulation& sim, const std::vector<std::int32_t>& parents,
                      StateMapping mapping, EventSearch* search, const CancelCheck& cancelled) {
  const auto ask = [&](const char* phase) {
    if (cancelled && cancelled())
      throw EventCancelled(std::string("refinement event cancelled ") + phase);
  };
  const auto start = std::chrono::steady_clock::now();
  RefinementEvent out;
  out.generation = sim.generation();
  if (parents.empty()) return out;
  if (sim.setup().model == ForceModel::ConstantHorizon)
    throw InputError(
        "refinement needs per-particle horizons: use model dual-horizon (or classical-variable), "
        "not constant-horizon");
  auto t = sim.timers().scope(Phase::Refine);
  EventSearch local;
  EventSearch& es = search ? *search : local;
  SpatialGrid& grid = es.grid(sim);
  EventScratch ev;
  ev.plan =
      plan_split(sim.particles(), parents, ChildFilter{sim.setup().body, sim.particles().dim()});
  if (ev.plan.parents.empty()) return out;
  ask("after planning");
  ev.parent_slot = &es.parent_slot;
  ev.child_of_slot = &es.child_of_slot;
  // The mapping's energy change, for the instability guard's balance: only rows near the parents
  // change (unchanged rows give the same bits before and after, and cancel).
  auto d = sim.begin_edit(event_energy_rows(sim, grid, ev.plan, cancelled), ev.plan.parents);
  write_event_children(sim, d, grid, ev, mapping, out, cancelled);
  ask("after writing the children");
  ev.owners = owners_to_rebuild(sim, grid, ev, cancelled);
  ask("after finding the rows to rebuild");
  rebuild_rows(sim, d, grid, ev, out, cancelled);
  const EditOutcome done = sim.commit_edit(change_of(ev), ev.broken_change);
  es.mark_current(sim);
  for (const auto q : ev.plan.parents) es.parent_slot[static_cast<std::size_t>(q)] = -1;
  for (const auto s : ev.plan.child_slot) es.child_of_slot[static_cast<std::size_t>(s)] = -1;
  out.interfaces = done.interfaces;
  out.energy_change = done.energy_change;
  out.shadow_change = done.shadow_change;
  const double mapped = sim.energy_budget().mapping;
  out.generation = sim.generation();
  out.parents = ev.plan.parents.size();
  out.children = ev.plan.child_slot.size();
  out.dropped = ev.plan.dropped;
  out.rows_touched = ev.dirty.size();
  out.bonds = static_cast<std::size_t>(sim.bonds().own_bonds);
  out.seconds = seconds_since(start);
  const auto& setup = sim.setup();
  const bool crowded = static_cast<double>(sim.appended_since_compaction()) >
                       setup.resort_fraction * static_cast<double>(sim.particles().size());
  const bool wasteful = 2 * sim.bonds().rows.garbage > sim.bonds().rows.arena;
  if (setup.resort_fraction > 0.0 && (crowded || wasteful)) {
    out.resorted = true;
    const auto compaction = std::chrono::steady_clock::now();
    sim.compact();
    es.grid(sim);  // renumbered slots: the grid is rebuilt now, as part of the compaction's cost
    out.resort_seconds = seconds_since(compaction);
  }
  // Multi-rate stepping: the time levels of the new particles (docs/theory.md §19); a renumbering
  // by level is a compaction too.
  const auto layout = sim.layout_version();
  const auto relevel = std::chrono::steady_clock::now();
  sim.relevel();
  // A compaction or new time levels move the shadow energy (docs/theory.md §19): the ledger's.
  out.shadow_change += sim.energy_budget().mapping - mapped;
  if (sim.layout_version() != layout) {
    out.resorted = true;
    es.grid(sim);
    out.resort_seconds += seconds_since(relevel);
  }
  return out;
}

}  // namespace dhpd::refine
