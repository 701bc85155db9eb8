// A refinement event applied to the stepper (dhpd.md §8; IJNME 2016 §5.3): split, rebuild from
// scratch, no healing, loads and stable step again.
#include <fmt/core.h>
#include <chrono>
#include <cmath>

#include "engine/errors.hpp"
#include "engine/kernels.hpp"
#include "engine/refinement_event.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

RefinementEvent Simulation::apply_refinement(const std::vector<std::int32_t>& parents,
                                             StateMapping mapping) {
  const auto start = std::chrono::steady_clock::now();
  RefinementEvent ev;
  ev.generation = generation_;
  if (parents.empty()) return ev;
  if (setup_.model == ForceModel::ConstantHorizon)
    throw InputError(
        "refinement needs per-particle horizons: use model dual-horizon (or classical-variable), "
        "not constant-horizon");
  auto t = timers_.scope(Phase::Refine);
  auto split = split_particles(p_, parents, setup_.section, next_id_);
  next_id_ += static_cast<std::int32_t>(split.children);
  map_displacement(split, mapping, p_, bonds_);
  BondList old_bonds = std::move(bonds_);
  ParticleStore old_p = std::move(p_);
  p_ = std::move(split.particles);
  for (std::size_t i = 0; i < p_.size(); ++i) {
    p_.no_fail[i] = 0;
    const geometry::Vec3 x{p_.reference_position[0][i], p_.reference_position[1][i],
                           p_.reference_position[2][i]};
    for (const auto& region : setup_.no_fail)
      if (region.contains(x, setup_.section.dim)) p_.no_fail[i] = 1;
  }
  update_bond_constants();
  bonds_ = build_bonds(p_, setup_.partial_volume, setup_.cracks);
  ev.started_broken = apply_no_healing(bonds_, p_, split.previous, split.kept, old_bonds, old_p);
  broken_ = 0;
  for (const auto f : bonds_.intact) broken_ += f ? 0 : 1;
  dual_ = build_dual(bonds_);
  il_ = build_interactions(setup_.model, bonds_, dual_, p_, C_);
  critical_dt_ = critical_time_step(il_, p_);
  // A fixed step stays while it is stable; otherwise the scene's safety applies to the new bound.
  const bool keep_fixed = setup_.fixed_dt && *setup_.fixed_dt <= critical_dt_;
  dt_ = keep_fixed ? *setup_.fixed_dt : setup_.safety * critical_dt_;
  loads_ = resolve_loads(setup_.boundary_conditions, p_);
  enforce_prescribed_velocity();
  compute_forces();
  last_power_ = boundary_power();
  if (setup_.effects.fracture) compute_damage(bonds_, p_);
  ++generation_;
  ev.generation = generation_;
  ev.parents = parents.size();
  ev.children = split.children;
  ev.bonds = bonds_.size();
  ev.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ev;
}

}  // namespace dhpd
