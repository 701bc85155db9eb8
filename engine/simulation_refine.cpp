// A refinement event applied to the stepper (dhpd.md §8; IJNME 2016 §5.3): split, rebuild the
// touched rows incrementally, no healing, then loads, stable step, forces and damage of the
// touched particles; and the occasional Morton re-sort with compaction.
#include <fmt/core.h>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/errors.hpp"
#include "engine/kernels.hpp"
#include "engine/refinement_scratch.hpp"
#include "geometry/lattice.hpp"

namespace dhpd {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

RefinementEvent Simulation::apply_refinement(const std::vector<std::int32_t>& parents,
                                             StateMapping mapping) {
  const auto start = std::chrono::steady_clock::now();
  RefinementEvent out;
  out.generation = generation_;
  if (parents.empty()) return out;
  if (setup_.model == ForceModel::ConstantHorizon)
    throw InputError(
        "refinement needs per-particle horizons: use model dual-horizon (or classical-variable), "
        "not constant-horizon");
  auto t = timers_.scope(Phase::Refine);
  ensure_grid();
  EventScratch ev;
  ev.plan = plan_split(p_, parents, ChildFilter{setup_.body, p_.dim()});
  const auto& plan = ev.plan;
  if (plan.parents.empty()) return out;
  // The mapping's energy change, for the instability guard's balance: only rows near the parents
  // change (unchanged rows give the same bits before and after, and cancel).
  auto energy_rows = event_energy_rows(plan);
  const double before =
      strain_energy_of_rows(bonds_, p_, C_, energy_rows) + kinetic_energy_of(p_, plan.parents);
  const double correction_before = verlet_correction();
  ev.parents = snapshot(p_, plan.parents);
  std::vector<std::int32_t> held(loads_.prescribed);
  std::sort(held.begin(), held.end());
  const auto state = map_state(plan, mapping, p_, bonds_, held,
                               donors_across_cracks(plan, p_, setup_.cracks, *grid_));
  out.reduced_fits = state.reduced_fits;
  ev.near = old_neighbourhood(plan);
  parent_slot_.resize(plan.new_size, -1);
  child_of_slot_.resize(plan.new_size, -1);
  touched_.resize(plan.new_size, 0);
  for (std::size_t k = 0; k < plan.parents.size(); ++k)
    parent_slot_[static_cast<std::size_t>(plan.parents[k])] = static_cast<std::int32_t>(k);
  write_children(p_, plan, ev.parents, state, setup_.section, next_id_);
  next_id_ += static_cast<std::int32_t>(plan.child_slot.size());
  for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
    const auto s = plan.child_slot[c];
    child_of_slot_[static_cast<std::size_t>(s)] = static_cast<std::int32_t>(c);
    // A parent's slot holds its first child: inserting it replaces the parent in the grid.
    grid_->insert(s, plan.child_position[c], p_.spacing[static_cast<std::size_t>(s)]);
  }
  ev.children = plan.child_slot;
  std::sort(ev.children.begin(), ev.children.end());
  update_bond_constants(ev.children);
  bonds_.rows.grow_rows(plan.new_size);
  dual_.rows.grow_rows(plan.new_size);
  il_.rows.grow_rows(plan.new_size);
  ev.owners = owners_to_rebuild(plan);
  rebuild_rows(ev, out);
  finish_event(ev, out);
  for (const auto c : plan.child_slot)  // appended children: rows that did not exist before
    if (static_cast<std::size_t>(c) >= plan.old_size) energy_rows.push_back(c);
  out.energy_change = strain_energy_of_rows(bonds_, p_, C_, energy_rows) +
                      kinetic_energy_of(p_, plan.child_slot) - before;
  // The shadow energy also moves with the new forces and the new dt (a pass over particles only).
  out.shadow_change = out.energy_change - (verlet_correction() - correction_before);
  budget_.mapping += out.shadow_change;
  out.seconds = seconds_since(start);
  const bool crowded = static_cast<double>(appended_since_sort_) >
                       setup_.resort_fraction * static_cast<double>(p_.size());
  const bool wasteful = 2 * bonds_.rows.garbage > bonds_.rows.arena;
  if (setup_.resort_fraction > 0.0 && (crowded || wasteful)) {
    out.resorted = true;
    out.resort_seconds = resort();
  }
  return out;
}

bool Simulation::corrects_interfaces() const {
  return setup_.interface_correction && setup_.model == ForceModel::DualHorizon;
}

void Simulation::finish_event(EventScratch& ev, RefinementEvent& out) {
  const auto& plan = ev.plan;
  // The rows the event touched hold every bond that changed: bonds with both ends among them are
  // solved again; the others keep their factors, and particles outside keep their bonds, so they
  // stay consistent (docs/theory.md §4).
  if (corrects_interfaces())
    out.interfaces = correct_level_interfaces(bonds_, dual_, p_, C_, ev.dirty);
  il_.own_slot.resize(bonds_.slots(), -1);
  il_.dual_slot.resize(bonds_.slots(), -1);
  for (const auto i : ev.dirty)
    rebuild_interaction_row(il_, static_cast<std::size_t>(i), setup_.model, bonds_, dual_, p_, C_);
  particle_time_steps(il_, p_, particle_dt_, &ev.dirty);
  critical_dt_ = smallest(particle_dt_);  // one double per particle: cheap next to the rebuild
  // A fixed step stays while it is stable; otherwise the scene's safety applies to the new bound.
  const bool keep_fixed = setup_.fixed_dt && *setup_.fixed_dt <= critical_dt_;
  dt_ = keep_fixed ? *setup_.fixed_dt : setup_.safety * critical_dt_;
  out.child_slot = plan.child_slot;
  for (const auto c : plan.child_parent) out.parent_slot.push_back(plan.parents[c]);
  update_loads_after_split(loads_, out.child_slot, out.parent_slot);
  enforce_prescribed_velocity();
  internal_force_density(il_, p_, &ev.dirty);
  for (const auto i : ev.dirty) touched_[static_cast<std::size_t>(i)] = 1;
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k)
    if (touched_[static_cast<std::size_t>(loads_.loaded[k])])
      for (int a = 0; a < p_.dim(); ++a)
        p_.force_density[a][loads_.loaded[k]] += loads_.body_force[k][a];
  last_power_ = boundary_power();
  if (setup_.effects.fracture) compute_damage(bonds_, p_, &ev.owners);
  for (const auto i : ev.dirty) touched_[static_cast<std::size_t>(i)] = 0;
  for (const auto q : plan.parents) parent_slot_[static_cast<std::size_t>(q)] = -1;
  for (const auto s : plan.child_slot) child_of_slot_[static_cast<std::size_t>(s)] = -1;
  appended_since_sort_ += plan.new_size - plan.old_size;
  ++generation_;
  out.generation = generation_;
  out.parents = plan.parents.size();
  out.children = plan.child_slot.size();
  out.dropped = plan.dropped;
  out.rows_touched = ev.dirty.size();
  out.bonds = bonds_.size();
}

double Simulation::resort() {
  const auto start = std::chrono::steady_clock::now();
  auto t = timers_.scope(Phase::Refine);
  const std::size_t n = p_.size();
  std::vector<geometry::Vec3> where(n);
  for (std::size_t i = 0; i < n; ++i) where[i] = point_of(p_.reference_position, i);
  const auto order = geometry::morton_order(where, p_.dim());  // order[k]: old index of new k
  std::vector<std::int32_t> new_index(n);
  for (std::size_t k = 0; k < n; ++k) new_index[static_cast<std::size_t>(order[k])] = k;
  p_ = snapshot(p_, order);
  // Bond rows in the new order, each sorted by neighbour as a from-scratch build leaves them.
  BondList b;
  std::vector<std::int32_t> counts(n);
  for (std::size_t k = 0; k < n; ++k) counts[k] = bonds_.rows.count[order[k]];
  b.rows = RowIndex::packed(counts);
  b.fit_arena();
  b.live = b.rows.arena;
  std::vector<std::pair<std::int32_t, std::int64_t>> row;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(order[k]);
    row.clear();
    for (auto e = bonds_.begin(i); e < bonds_.end(i); ++e)
      row.emplace_back(new_index[static_cast<std::size_t>(bonds_.neighbor[e])], e);
    std::sort(row.begin(), row.end());
    auto s = static_cast<std::size_t>(b.begin(k));
    for (const auto& [j, e] : row) {
      b.owner[s] = static_cast<std::int32_t>(k);
      b.neighbor[s] = j;
      b.length[s] = bonds_.length[e];
      b.weight[s] = bonds_.weight[e];
      b.stiffness[s] = bonds_.stiffness[e];
      b.intact[s++] = bonds_.intact[e];
    }
  }
  bonds_ = std::move(b);
  dual_ = build_dual(bonds_);
  update_bond_constants();
  il_ = build_interactions(setup_.model, bonds_, dual_, p_, C_);
  particle_time_steps(il_, p_, particle_dt_);
  renumber_loads(loads_, new_index);
  grid_.reset();
  ensure_grid();
  parent_slot_.assign(n, -1);
  child_of_slot_.assign(n, -1);
  touched_.assign(n, 0);
  compute_forces();
  if (setup_.effects.fracture) compute_damage(bonds_, p_);
  appended_since_sort_ = 0;
  return seconds_since(start);
}

}  // namespace dhpd
