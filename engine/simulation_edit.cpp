// The edit seam of the stepper (docs/design.md): an editor (refine/) rewrites particles and bond
// rows; the engine derives the rows' stiffness, constants, stable steps, loads, forces, damage and
// the energy ledger of what changed; and compaction renumbers everything in Morton order.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"

namespace dhpd {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// new_index[order[k]] = k.
std::vector<std::int32_t> inverse_order(const std::vector<std::int32_t>& order) {
  std::vector<std::int32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
  return new_index;
}
}  // namespace

bool Simulation::corrects_interfaces() const {
  return setup_.interface_correction && setup_.model == ForceModel::DualHorizon &&
         setup_.family != ModelFamily::Correspondence;
}

Simulation::Discretisation Simulation::begin_edit(std::vector<std::int32_t> energy_rows,
                                                  const std::vector<std::int32_t>& moving) {
  if (edit_) throw EngineError("begin_edit: an edit is already open");
  // The correspondence family's level interfaces carry a force layer that no correction removes
  // yet (docs/theory.md §21.3).
  if (correspondence_)
    throw InputError("refinement is not available with the correspondence family");
  if (setup_.model == ForceModel::MultiHorizon)
    throw InputError("refinement is not offered with model multi-horizon (α fixed at the start)");
  if (setup_.model == ForceModel::ConstantHorizon)
    throw InputError(
        "refinement needs per-particle horizons: use model dual-horizon (or classical-variable), "
        "not constant-horizon");
  // Unchanged rows give the same bits before and after and cancel: only the named rows count
  // (bond-based; the state-based energy is the whole body's, θ coupling every row to its partners).
  OpenEdit e;
  e.energy_before = (state_ ? state_->strain_energy(bonds_, p_)
                            : strain_energy_of_rows(bonds_, p_, energy_rows)) +
                    kinetic_energy_of(p_, moving);
  e.correction_before = verlet_correction();
  e.energy_rows = std::move(energy_rows);
  edit_ = std::move(e);
  return {p_, bonds_};
}

void Simulation::particles_written(const std::vector<std::int32_t>& slots) {
  if (!edit_) throw EngineError("particles_written outside an edit");
  std::vector<std::int32_t> sorted(slots);
  std::sort(sorted.begin(), sorted.end());
  update_bond_constants(sorted);
  bonds_.rows.grow_rows(p_.size());
  bonds_.break_ratio2.resize(p_.size(), HUGE_VAL);
}

std::int32_t Simulation::take_ids(std::size_t n) {
  const std::int32_t first = next_id_;
  next_id_ += static_cast<std::int32_t>(n);
  return first;
}

EditOutcome Simulation::commit_edit(const DiscretisationChange& change,
                                    std::int64_t broken_bonds_change) {
  if (!edit_) throw EngineError("commit_edit without begin_edit");
  drop_stretch_watch();  // new particles and rows: the watcher sets new limits
  EditOutcome out;
  const auto& dirty = change.changed_rows;
  broken_ += broken_bonds_change;
  // The rows the edit touched hold every bond that changed: bonds with both ends among them are
  // solved again; the others keep their factors, and particles outside keep their bonds, so they
  // stay consistent (docs/theory.md §14).
  std::optional<OrdinaryState> built;  // the state-based model of the corrected rows
  if (corrects_interfaces()) out.interfaces = correct_interfaces(dirty, &built);
  const auto constants = bond_constants();
  for (const auto i : dirty) refresh_row(bonds_, constants, static_cast<std::size_t>(i));
  if (state_ && built)
    state_ = std::move(built);
  else if (state_)
    build_state_model();
  particle_time_steps(bonds_, p_, particle_dt_, &dirty);
  critical_dt_ = estimate_critical_dt();
  // A fixed step stays while it is stable; otherwise the scene's safety applies to the new step.
  // (A static run's dt is its load increment.)
  const bool keep_fixed = setup_.fixed_dt && *setup_.fixed_dt <= critical_dt_;
  if (!setup_.statics) dt_ = keep_fixed ? *setup_.fixed_dt : setup_.safety * critical_dt_;
  // One global step at the finest particles' dt until relevel(); the plans stay as former plans.
  former_.reset();
  if (levels_) former_ = FormerPlans{std::move(*levels_), {}, -1, -1};
  levels_.reset();
  inherit_loads(loads_, change.successor, change.predecessor);
  enforce_prescribed_velocity();
  // State-based: θ couples each row to its partners, so every particle's force is new (and gets
  // its body force again); bond-based: only the rewritten rows'.
  const bool every_row = state_.has_value();
  if (every_row)
    state_->forces(bonds_, p_);
  else
    internal_force_density(bonds_, p_, &dirty, nullptr, &kernel_points_);
  touched_.resize(p_.size(), 0);
  for (const auto i : dirty) touched_[static_cast<std::size_t>(i)] = 1;
  const double lambda = load_factor();  // 1 in dynamics
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k)
    if (every_row || touched_[static_cast<std::size_t>(loads_.loaded[k])])
      for (int a = 0; a < p_.dim(); ++a)
        p_.force_density[a][loads_.loaded[k]] += lambda * loads_.body_force[k][a];
  for (const auto i : dirty) touched_[static_cast<std::size_t>(i)] = 0;
  last_power_ = boundary_power();
  if (setup_.effects.fracture)
    compute_damage(bonds_, p_, setup_.partial_volume, &change.rewritten_rows);
  appended_since_compaction_ += p_.size() - change.old_size;
  ++generation_;
  if (former_) {  // the rows the edit rewrote (new particles among them) are evaluated again
    former_->recompute.assign(p_.size(), 0);
    for (const auto i : dirty) former_->recompute[static_cast<std::size_t>(i)] = 1;
    former_->generation = generation_;
    former_->layout = layout_version_;
  }
  // The energy ledger: the named rows again, with the appended particles' rows after them.
  auto rows = std::move(edit_->energy_rows);
  for (const auto c : change.new_particles)
    if (static_cast<std::size_t>(c) >= change.old_size) rows.push_back(c);
  out.energy_change =
      (state_ ? state_->strain_energy(bonds_, p_) : strain_energy_of_rows(bonds_, p_, rows)) +
      kinetic_energy_of(p_, change.new_particles) - edit_->energy_before;
  // The shadow energy also moves with the new forces and the new dt (a pass over particles only).
  out.shadow_change = out.energy_change - (verlet_correction() - edit_->correction_before);
  budget_.mapping += out.shadow_change;
  edit_.reset();
  if (share_) {  // every rank runs the same edit: the new particles get owners (§25.3)
    const auto in = partition_input();
    share_->after_edit(change.old_size, p_.dim(), in.xyz, in.weight, in.id);
  }
  return out;
}

double Simulation::compact() {
  const auto start = std::chrono::steady_clock::now();
  // New time levels change the shadow energy's correction: the ledger takes it as a mapping.
  const double before = verlet_correction();
  renumber();
  budget_.mapping -= verlet_correction() - before;
  return seconds_since(start);
}

void Simulation::renumber() {
  auto t = timers_.scope(Phase::Refine);
  const std::size_t n = p_.size();
  std::vector<geometry::Vec3> where(n);
  for (std::size_t i = 0; i < n; ++i) where[i] = point_of(p_.reference_position, i);
  auto order = geometry::morton_order(where, p_.dim());  // order[k]: old index of new k
  if (multirate_enabled()) {  // by time level first (docs/theory.md §19)
    const auto choice = choose_levels();
    if (choice.count > 1) order = order_by_level(order, choice.level);
  }
  const auto new_index = inverse_order(order);
  drop_stretch_watch();  // its limits are by index
  former_.reset();       // every row moves: every level force is evaluated again
  p_ = gather(p_, order);
  // Refinement moves the rows it rebuilds to the end of the arena: room for an eighth more.
  bonds_ = renumbered_rows(bonds_, order, new_index, setup_.effects.refinement ? 0.125 : 0.0);
  renumber_per_particle(order, new_index);
  update_bond_constants();
  if (state_) build_state_model();
  particle_time_steps(bonds_, p_, particle_dt_);
  compute_forces();
  if (setup_.effects.fracture) compute_damage(bonds_, p_, setup_.partial_volume);
  plan_levels();
  appended_since_compaction_ = 0;
  ++layout_version_;
}

void Simulation::regroup_by_level(const std::vector<std::int8_t>& level) {
  auto t = timers_.scope(Phase::Refine);
  const auto order = fewest_moves_by_level(level);
  std::vector<std::int32_t> moved;
  for (std::size_t k = 0; k < order.size(); ++k)
    if (order[k] != static_cast<std::int32_t>(k)) moved.push_back(static_cast<std::int32_t>(k));
  const auto new_index = inverse_order(order);
  drop_stretch_watch();  // its limits are by index
  permute_slots(p_, order, moved);
  const auto rows = renumber_rows_in_place(bonds_, order, new_index, moved);
  if (auto* former = current_former())  // moved and re-sorted rows: their forces anew
    for (const auto i : rows) former->recompute[static_cast<std::size_t>(i)] = 1;
  renumber_per_particle(order, new_index);
  for (auto* values : {&C_, &s0_, &particle_dt_}) move_slots(*values, order, moved);
  if (state_) build_state_model();
  // The re-sorted rows sum their entries in a new order: their bounds and damage again.
  particle_time_steps(bonds_, p_, particle_dt_, &rows);
  if (setup_.effects.fracture) compute_damage(bonds_, p_, setup_.partial_volume, &rows);
  plan_levels();  // every level's forces at the current positions (kept where they are)
  if (!levels_) compute_forces();
  // Out of Morton place, like appended particles: a compaction restores the order.
  appended_since_compaction_ += moved.size();
  ++layout_version_;
  slot_moves_.layout = layout_version_;
  slot_moves_.source.resize(moved.size());
  for (std::size_t t = 0; t < moved.size(); ++t)
    slot_moves_.source[t] = order[static_cast<std::size_t>(moved[t])];
  slot_moves_.moved = std::move(moved);
}

void Simulation::renumber_per_particle(const std::vector<std::int32_t>& order,
                                       const std::vector<std::int32_t>& new_index) {
  const std::size_t n = order.size();
  if (!interaction_scale_.empty()) {  // two per particle (multi-horizon; never edited today)
    std::vector<double> scale(interaction_scale_.size());
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t side = 0; side < 2; ++side)
        scale[2 * k + side] = interaction_scale_[2 * static_cast<std::size_t>(order[k]) + side];
    interaction_scale_ = std::move(scale);
  }
  renumber_loads(loads_, new_index);
  touched_.assign(n, 0);
  if (share_) share_->renumbered(order);
}

}  // namespace dhpd
