// Set-up and velocity-Verlet stepping of bond-based DH-PD (dhpd.md §3–5, §7).
#include "engine/simulation.hpp"
#include "engine/parallel.hpp"

#include <fmt/core.h>
#include <algorithm>
#include <cmath>

#include "engine/errors.hpp"
#include "engine/kernels.hpp"

namespace dhpd {

Simulation::Simulation(const SimulationSetup& setup) : setup_(setup), p_(setup.section.dim) {
  {
    auto t = timers_.scope(Phase::Search);
    init_particles();
    bonds_ = build_bonds(p_, setup_.partial_volume, setup_.cracks);
    dual_ = build_dual(bonds_);
    il_ = build_interactions(setup_.model, bonds_, dual_, p_, C_);
  }
  particle_time_steps(il_, p_, particle_dt_);
  critical_dt_ = smallest(particle_dt_);
  if (!std::isfinite(critical_dt_))
    throw InputError("no particle has a bond: the horizon factor or spacing is too small");
  dt_ = setup_.fixed_dt.value_or(setup_.safety * critical_dt_);
  loads_ = resolve_loads(setup_.boundary_conditions, p_);
  enforce_prescribed_velocity();
  compute_forces();
  last_power_ = boundary_power();
  const auto e = energies();
  initial_energy_ = e.kinetic + e.strain;
  reach_ = BondRowBuilder::exact_reach(p_, setup_.partial_volume);
  for (std::size_t i = 0; i < p_.size(); ++i) max_horizon_ = std::max(max_horizon_, p_.horizon[i]);
  if (setup_.effects.refinement) ensure_grid();
}

void Simulation::init_particles() {
  auto pts = setup_.points;
  std::vector<std::int32_t> order(pts.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::int32_t>(k);
  if (setup_.spatial_sort) {
    order = geometry::morton_order(pts.position, setup_.section.dim);
    pts = geometry::permuted(pts, order);
  }
  const std::size_t n = pts.size();
  p_.resize(n);
  double max_spacing = 0.0;
  for (std::size_t i = 0; i < n; ++i) max_spacing = std::max(max_spacing, pts.spacing[i]);
  next_id_ = static_cast<std::int32_t>(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a)
      p_.reference_position[a][i] = p_.position[a][i] = pts.position[i][a];
    const auto& mat = setup_.materials.at(static_cast<std::size_t>(pts.material[i]));
    p_.spacing[i] = pts.spacing[i];
    const double spacing =
        setup_.model == ForceModel::ConstantHorizon ? max_spacing : pts.spacing[i];
    p_.horizon[i] = setup_.horizon_factor * spacing;
    p_.volume[i] = setup_.section.volume_of_cell(pts.cell_measure[i]);
    p_.density[i] = mat.rho;
    p_.material[i] = pts.material[i];
    p_.id[i] = order[i];
    p_.parent_id[i] = -1;
    const geometry::Vec3 x = pts.position[i];
    for (const auto& region : setup_.no_fail)
      if (region.contains(x, setup_.section.dim)) p_.no_fail[i] = 1;
  }
  set_particle_radii(p_, setup_.section);
  update_bond_constants();
  for (const auto& ic : setup_.initial_conditions) apply_initial_condition(ic, p_);
}

void Simulation::update_bond_constants() {
  std::vector<std::int32_t> all(p_.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
  update_bond_constants(all);
}

void Simulation::update_bond_constants(const std::vector<std::int32_t>& slots) {
  C_.resize(p_.size());
  s0_.resize(p_.size());
  for (const auto i : slots) {
    const auto& mat = setup_.materials.at(static_cast<std::size_t>(p_.material[i]));
    C_[i] = dhpd::micromodulus(mat, setup_.section, p_.horizon[i]);
    s0_[i] = mat.G0 > 0 ? dhpd::critical_stretch(mat, setup_.section, p_.horizon[i]) : HUGE_VAL;
  }
}

void Simulation::compute_forces() {
  {
    auto t = timers_.scope(Phase::Forces);
    internal_force_density(il_, p_);
  }
  auto t = timers_.scope(Phase::Loads);
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k)
    for (int a = 0; a < p_.dim(); ++a)
      p_.force_density[a][loads_.loaded[k]] += loads_.body_force[k][a];
}

void Simulation::enforce_prescribed_velocity() {
  for (std::size_t k = 0; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a)
      if (loads_.mask[k][a]) p_.velocity[a][i] = loads_.prescribed_velocity[k][a];
  }
}

double Simulation::boundary_power() const {
  // A prescribed constant velocity needs a reaction −f_int (per volume) on each constrained
  // component; its power is that reaction times the velocity.
  double power = 0.0;
  for (std::size_t k = 0; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a)
      if (loads_.mask[k][a])
        power -= p_.force_density[a][i] * p_.volume[i] * loads_.prescribed_velocity[k][a];
  }
  return power;
}

void Simulation::step() {
  const double h = 0.5 * dt_;
  const auto n = static_cast<std::int64_t>(p_.size());
  const int dim = p_.dim();
  double body_work = 0.0;
  {
    auto t = timers_.scope(Phase::Integrate);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
    for (std::int64_t i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) p_.velocity[a][i] += h * p_.force_density[a][i] / p_.density[i];
    enforce_prescribed_velocity();
    for (std::size_t k = 0; k < loads_.loaded.size(); ++k) {
      const auto i = loads_.loaded[k];
      for (int a = 0; a < dim; ++a)
        body_work += loads_.body_force[k][a] * p_.velocity[a][i] * dt_ * p_.volume[i];
    }
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
    for (std::int64_t i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) {
        p_.displacement[a][i] += dt_ * p_.velocity[a][i];
        p_.position[a][i] = p_.reference_position[a][i] + p_.displacement[a][i];
      }
  }
  if (setup_.effects.fracture) {
    auto t = timers_.scope(Phase::Fracture);
    broken_ += break_bonds(bonds_, il_, p_, s0_);
  }
  compute_forces();
  {
    auto t = timers_.scope(Phase::Integrate);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
    for (std::int64_t i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) p_.velocity[a][i] += h * p_.force_density[a][i] / p_.density[i];
    enforce_prescribed_velocity();
  }
  if (!state_is_finite())
    throw InstabilityError(fmt::format(
        "the state became non-finite (NaN/Inf) at step {} (t = {:.6g} s); reduce time.safety or "
        "time.dt, or check the loads",
        steps_ + 1, time_ + dt_));
  const double power = boundary_power();
  external_work_ += body_work + 0.5 * dt_ * (power + last_power_);
  last_power_ = power;
  time_ += dt_;
  ++steps_;
  interaction_updates_ += static_cast<std::int64_t>(il_.size());
}

bool Simulation::state_is_finite() const {
  // A NaN or Inf anywhere reaches the velocities within a step. v · 0 is 0 for every finite v
  // and NaN for NaN or Inf, so the sum is NaN exactly when some velocity is not finite.
  const auto n = static_cast<std::int64_t>(p_.size());
  double sum = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : sum) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i)
    for (int a = 0; a < p_.dim(); ++a) sum += p_.velocity[a][i] * 0.0;
  return std::isfinite(sum);
}

Energies Simulation::energies() {
  auto t = timers_.scope(Phase::Diagnostics);
  const std::size_t n = p_.size();
  std::vector<double> w;
  strain_energy_density(bonds_, p_, C_, w);
  std::vector<double> kin(n);
  Energies e;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> mom(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) mom[i] = p_.density[i] * p_.volume[i] * p_.velocity[a][i];
    e.momentum[a] = ordered_sum(mom);
  }
  for (std::size_t i = 0; i < n; ++i) {
    double v2 = 0.0;
    for (int a = 0; a < p_.dim(); ++a) v2 += p_.velocity[a][i] * p_.velocity[a][i];
    kin[i] = 0.5 * p_.density[i] * p_.volume[i] * v2;
    w[i] *= p_.volume[i];
  }
  e.kinetic = ordered_sum(kin);
  e.strain = ordered_sum(w);
  e.external_work = external_work_;
  return e;
}

void Simulation::check_stable(const Energies& e) const {
  const double total = e.kinetic + e.strain;
  if (!std::isfinite(total) || !std::isfinite(e.external_work))
    throw InstabilityError(fmt::format(
        "the state became non-finite (NaN/Inf) at step {} (t = {:.6g} s)", steps_, time_));
  const double budget = initial_energy_ + std::abs(e.external_work);
  // A stable run keeps KE + SE ≈ initial + external work; an explicit instability grows
  // exponentially. 100× the budget is far outside any Verlet oscillation.
  if (budget > 0.0 && total > 100.0 * budget)
    throw InstabilityError(fmt::format(
        "energy blow-up at step {} (t = {:.6g} s): kinetic + strain = {:.6g} J but initial + "
        "external work = {:.6g} J; reduce time.safety or time.dt",
        steps_, time_, total, budget));
}

void Simulation::update_damage() {
  auto t = timers_.scope(Phase::Fracture);
  compute_damage(bonds_, p_);
}

}  // namespace dhpd
