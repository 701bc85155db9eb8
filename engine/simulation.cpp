// Set-up and velocity-Verlet stepping of bond-based DH-PD (docs/theory.md §4, §8–10).
#include "engine/simulation.hpp"
#include "engine/base/parallel.hpp"

#include <fmt/core.h>
#include <omp.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/multi_horizon.hpp"
#include "engine/physics/stable_step.hpp"

namespace dhpd {

Simulation::Simulation(SimulationSetup setup)
    : setup_(std::move(setup)), fingerprint_(setup_fingerprint(setup_)), p_(setup_.section.dim) {
  {
    auto t = timers_.scope(Phase::Search);
    init_particles();  // takes the points out of setup_
    resolve_layers();
    bonds_ = build_bond_rows(p_, setup_.partial_volume, setup_.cracks);
    if (setup_.model == ForceModel::MultiHorizon)
      interaction_scale_ = interaction_scales(bonds_, p_, C_);
    std::optional<OrdinaryState> built;  // the state-based model of the corrected rows
    if (corrects_interfaces()) initial_interfaces_ = correct_interfaces({}, &built);
    refresh_rows(bonds_, bond_constants(), true);
    if (built)
      state_ = std::move(built);
    else
      build_state_model();
  }
  {
    auto t = timers_.scope(Phase::Search);  // set-up, as the bonds
    particle_time_steps(bonds_, p_, particle_dt_);
    critical_dt_ = estimate_critical_dt();
  }
  if (!std::isfinite(critical_dt_))
    throw InputError("no particle has a bond: the horizon factor or spacing is too small");
  dt_ = setup_.statics ? 1.0 / static_cast<double>(setup_.load_steps)
                       : setup_.fixed_dt.value_or(setup_.safety * critical_dt_);
  loads_ = resolve_loads(setup_.boundary_conditions, p_);
  for (const auto& bc : setup_.boundary_conditions)
    for (const auto& f : bc.in_time) has_time_functions_ = has_time_functions_ || !f.empty();
  first_layer_entry_ = loads_.prescribed.size();
  for (const auto& layer : layers_)  // held, not integrated: their displacements follow the rule
    for (const auto i : layer.particle) {
      loads_.prescribed.push_back(i);
      loads_.mask.push_back({1, 1, 1});
      loads_.prescribed_velocity.push_back({0, 0, 0});
      loads_.prescribed_displacement.push_back({0, 0, 0});
      loads_.condition.push_back(-1);
    }
  apply_prescribed_displacement(loads_, setup_.boundary_conditions, load_factor(),
                                setup_.statics ? load_factor() : time_, p_);
  enforce_prescribed_velocity();
  apply_layers();
  compute_forces();
  if (setup_.effects.fracture)
    compute_damage(bonds_, p_, setup_.partial_volume);  // then kept current by each step
  // Several time levels (docs/theory.md §19): particles renumbered by level, the levels planned.
  if (multirate_enabled() && choose_levels().count > 1) renumber();
  last_power_ = boundary_power();
  const auto e = energies();
  budget_.tolerance = setup_.energy_tolerance;
  // Classical and multi-horizon BB-PD with varying horizons are not conservative (unbalanced pair
  // forces do work): only non-finite states and blow-ups far beyond the balance stop them.
  conservative_ = conserves_momentum(setup_.model);
  blowup_factor_ = conservative_ ? 2.0 : 100.0;
  budget_.initial = e.kinetic - e.verlet_correction + e.strain;
  budget_.observe(0.0);
  reach_ = BondRowBuilder::exact_reach(p_, setup_.partial_volume);
  for (std::size_t i = 0; i < p_.size(); ++i) max_horizon_ = std::max(max_horizon_, p_.horizon[i]);
}

double Simulation::estimate_critical_dt() {
  const double bound = smallest(particle_dt_);
  // Lanczos needs M⁻¹K symmetric in the mass inner product: the classical variable-horizon and
  // multi-horizon models' unbalanced pairs make it not, so they keep the bound (docs/theory.md §9).
  if (!std::isfinite(bound) ||
      (!state_based() && (setup_.stable_step == StableStepEstimate::ParticleBound ||
                          !conserves_momentum(setup_.model))))
    return bound;
  // After an edit that leaves the smallest per-particle bound where the last Lanczos estimate
  // found it (new particles like the stiffest ones already there), the top of the spectrum is
  // where it was: the estimate follows the bound's smallest value instead of iterating again
  // (tens of force passes per event); a stiffer particle, as at the first split to a new level,
  // runs Lanczos anew (docs/theory.md §9).
  if (lanczos_bound_ > 0.0 && bound >= 0.99 * lanczos_bound_) {
    const double followed = lanczos_dt_ * std::min(1.0, bound / lanczos_bound_);
    return state_based() ? followed : std::max(bound, followed);
  }
  lanczos_dt_ = state_based() ? state_lanczos_dt()
                              : lanczos_stable_step(bonds_, p_, 80, 1e-4, &particle_dt_).dt;
  lanczos_bound_ = bound;
  // particle_dt_ is the bond-based bound of the same E: a guide for the start vector and for when
  // to iterate again, not a bound of the state-based model (docs/theory.md §20.3).
  return state_based() ? lanczos_dt_ : std::max(bound, lanczos_dt_);
}

void Simulation::init_particles() {
  auto pts = std::move(setup_.points);
  setup_.points = {};
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
  if (setup_.family == ModelFamily::OrdinaryState && state_phi_.empty())
    for (const auto& m : setup_.materials)
      state_phi_.push_back(state_fracture_factor(m, setup_.section, setup_.influence));
  for (const auto i : slots) {
    const auto& mat = setup_.materials.at(static_cast<std::size_t>(p_.material[i]));
    C_[i] = dhpd::micromodulus(mat, setup_.section, p_.horizon[i]);
    s0_[i] = !(mat.G0 > 0) ? HUGE_VAL
             : setup_.family == ModelFamily::OrdinaryState
                 ? std::sqrt(mat.G0 /
                             (state_phi_[static_cast<std::size_t>(p_.material[i])] * p_.horizon[i]))
                 : dhpd::critical_stretch(mat, setup_.section, p_.horizon[i]);
  }
}

BondConstants Simulation::bond_constants() const {
  return {setup_.model, setup_.partial_volume, p_, C_, s0_, interaction_scale_};
}

void Simulation::compute_forces(bool with_fracture, std::vector<double>* row_energy,
                                const SideTask* side) {
  {
    auto t = timers_.scope(Phase::Forces);
    if (correspondence_ && share_) {
      distributed_correspondence_forces();
    } else if (correspondence_) {
      correspondence_->forces(bonds_, p_);  // elastic: no fracture (refused by the scene)
    } else if (state_ && share_) {
      distributed_state_forces(with_fracture);
    } else if (state_) {
      // Breaks first: the dilatation sums the bonds left (docs/theory.md §20.4).
      if (with_fracture) broken_ += break_bonds(bonds_, p_, bond_constants());
      state_->forces(bonds_, p_);
    } else if (share_) {
      distributed_forces(with_fracture, row_energy, side);
    } else if (with_fracture)
      broken_ += force_and_break(bonds_, p_, bond_constants(), row_energy, &kernel_points_, side,
                                 nullptr, stretch_watch_into(watch_.hit));
    else
      internal_force_density(bonds_, p_, nullptr, row_energy, &kernel_points_, side);
  }
  auto t = timers_.scope(Phase::Loads);
  const double lambda = load_factor();  // 1 in dynamics
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k)
    for (int a = 0; a < p_.dim(); ++a)
      p_.force_density[a][loads_.loaded[k]] += lambda * loads_.body_force[k][a];
}

void Simulation::step(StepExtras extras) {
  std::int64_t evaluated = bonds_.own_bonds;  // directed bonds evaluated by the step
  if (share_) {
    if (share_->comm().root())
      share_->announce(extras.strain_energy ? distributed::Command::StepWithEnergy
                                            : distributed::Command::Step);
    if (share_->policy() == distributed::RepartitionPolicy::Steps) {
      // A row's bond states are current only on its owner: every rank takes them before any
      // row changes owner (all ranks are here: no announcement).
      if (!bonds_shared_) share_->share_bond_states(bonds_, bond_constants());
      bonds_shared_ = true;
      const auto in = partition_input();
      share_->repartition(p_.dim(), in.xyz, in.weight, in.id);
    }
    bonds_shared_ = bonds_shared_ && !setup_.effects.fracture;  // this step's pass breaks bonds
  }
  if (setup_.statics) {
    finish_step(static_step(extras));
    time_ = load_factor();  // k / load_steps exactly, not a sum of steps
    bond_updates_ += evaluated * (relaxation_report_.iterations + relaxation_report_.rounds + 1);
    return;
  }
  if (has_time_functions_) {
    // The supports also accelerate what they hold: that work is the held kinetic energy's change.
    const double before = held_kinetic_energy();
    update_prescribed_velocity(loads_, setup_.boundary_conditions, time_, dt_);
    external_work_ += held_kinetic_energy() - before;
  }
  watch_.current = false;
  const double body_work = levels_ ? multirate_step(extras, evaluated) : verlet_step(extras);
  if (stretch_watched() && setup_.effects.fracture && !state_based() && !share_) {
    if (levels_) merge_level_watch();
    watch_.current = true;
  }
  finish_step(body_work);
  bond_updates_ += evaluated;
  if (extras.strain_energy && !levels_ && !state_based()) {
    auto t = timers_.scope(Phase::Diagnostics);
    fused_energy_.strain = strain_energy_of_row_sums(fused_energy_.rows, p_);
    fused_energy_.step = steps_;
    fused_energy_.generation = generation_;
    fused_energy_.layout = layout_version_;
  }
}

double Simulation::verlet_step(const StepExtras& extras) {
  const double h = 0.5 * dt_;
  const auto n = static_cast<std::int64_t>(p_.size());
  const int dim = p_.dim();
  double body_work = 0.0;
  {
    auto t = timers_.scope(Phase::Integrate);
#pragma omp parallel if (n >= kParallelMinParticles)
    {
      const auto [begin, end] = team_range(n, omp_get_thread_num(), omp_get_num_threads());
      if (extras.before_change) (*extras.before_change)(begin, end);
      for (std::int64_t i = begin; i < end; ++i)
        for (int a = 0; a < dim; ++a)
          p_.velocity[a][i] += h * p_.force_density[a][i] / p_.density[i];
    }
    enforce_prescribed_velocity();
    for (std::size_t k = 0; k < loads_.loaded.size(); ++k) {
      const auto i = loads_.loaded[k];
      for (int a = 0; a < dim; ++a)
        body_work += loads_.body_force[k][a] * p_.velocity[a][i] * dt_ * p_.volume[i];
    }
    // The new positions go to the kernel's packed points as well (kernel::pack_points, the same
    // values), which spares the force pass its own pass over the particles.
    auto& points = kernel_points_.xyzv;
    points.resize(4 * p_.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
    for (std::int64_t i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) {
        if (a >= dim) {
          points[4 * i + a] = 0.0;
          continue;
        }
        p_.displacement[a][i] += dt_ * p_.velocity[a][i];
        p_.position[a][i] = p_.reference_position[a][i] + p_.displacement[a][i];
        points[4 * i + a] = p_.position[a][i];
      }
      points[4 * i + 3] = p_.volume[i];
    }
    kernel_points_.fresh = true;
  }
  // Fictitious layers follow the body's new positions; their supports' work enters the ledger.
  std::optional<HeldState> layers_before;
  if (!layers_.empty()) {
    layers_before = held_state(first_layer_entry_);
    apply_layers();
    auto& points = kernel_points_.xyzv;
    for (const auto& layer : layers_)
      for (const auto i : layer.particle)
        for (int a = 0; a < dim; ++a) points[4 * i + a] = p_.position[a][i];
  }
  compute_forces(setup_.effects.fracture, extras.strain_energy ? &fused_energy_.rows : nullptr,
                 extras.side_task);
  if (layers_before) body_work += held_work(*layers_before);
  {
    auto t = timers_.scope(Phase::Integrate);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
    for (std::int64_t i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) p_.velocity[a][i] += h * p_.force_density[a][i] / p_.density[i];
    enforce_prescribed_velocity();
  }
  return body_work;
}

void Simulation::finish_step(double body_work) {
  const double power = boundary_power();
  const double work = external_work_ + body_work + 0.5 * dt_ * (power + last_power_);
  {
    auto t = timers_.scope(Phase::Diagnostics);
    const double kinetic = blocked_kinetic_energy(p_, kinetic_blocks_);
    if (!std::isfinite(kinetic) || !std::isfinite(work))
      stop_unstable("kinetic energy", std::numeric_limits<double>::quiet_NaN(), 0.0, steps_ + 1,
                    time_ + dt_);
    budget_.observe(work);
    // Strain energy is ≥ 0, so the kinetic energy alone may not pass the blow-up bound.
    const double blow_up = budget_.blow_up(work, blowup_factor_);
    if (kinetic > blow_up)
      stop_unstable("kinetic energy (blow-up bound)", kinetic, blow_up, steps_ + 1, time_ + dt_);
  }
  external_work_ = work;
  last_power_ = power;
  time_ += dt_;
  ++steps_;
}

namespace {
/// Momentum, kinetic energy and the Verlet correction summed over fixed blocks of particles (one
/// parallel pass; blocks added in order, so the same bits for any thread count).
struct ParticleSums {
  double momentum[3] = {0, 0, 0};
  double kinetic = 0.0;
  double correction = 0.0;  ///< (dt²/8) Σ V |f|²/ρ over components without prescribed velocity
  ParticleSums& operator+=(const ParticleSums& o) {
    for (int a = 0; a < 3; ++a) momentum[a] += o.momentum[a];
    kinetic += o.kinetic;
    correction += o.correction;
    return *this;
  }
};

ParticleSums particle_sums(const ParticleStore& p, const ResolvedLoads& loads, double dt) {
  const auto fixed = prescribed_axes(loads, p.size());
  const int dim = p.dim();
  return blocked_sum<ParticleSums>(p.size(), [&](std::size_t i, ParticleSums& s) {
    const double m = p.density[i] * p.volume[i];
    double v2 = 0.0, f2 = 0.0;
    for (int a = 0; a < 3; ++a) s.momentum[a] += m * p.velocity[a][i];
    for (int a = 0; a < dim; ++a) {
      v2 += p.velocity[a][i] * p.velocity[a][i];
      if (!(fixed[i] >> a & 1u)) f2 += p.force_density[a][i] * p.force_density[a][i];
    }
    s.kinetic += 0.5 * m * v2;
    s.correction += 0.125 * dt * dt * p.volume[i] * f2 / p.density[i];
  });
}
}  // namespace

Energies Simulation::energies() {
  auto t = timers_.scope(Phase::Diagnostics);
  // A static state is at rest: no Verlet correction (its dt is a load increment).
  const auto sums = particle_sums(p_, loads_, setup_.statics ? 0.0 : dt_);
  Energies e;
  for (int a = 0; a < 3; ++a) e.momentum[a] = sums.momentum[a];
  e.kinetic = sums.kinetic;
  if (correspondence_)
    e.strain = correspondence_->strain_energy(bonds_, p_);  // elastic: every rank's bonds intact
  else if (state_) {
    share_bond_states();  // the strain energy reads every row's bonds
    e.strain = state_->strain_energy(bonds_, p_);
  } else if (strain_energy_from_step())
    e.strain = fused_energy_.strain;
  else {
    share_bond_states();
    e.strain = strain_energy_total(bonds_, p_);
  }
  e.external_work = external_work_;
  e.verlet_correction = levels_ ? multirate_correction() : sums.correction;
  return e;
}

double Simulation::verlet_correction() const {
  return levels_          ? multirate_correction()
         : setup_.statics ? 0.0
                          : particle_sums(p_, loads_, dt_).correction;
}

void Simulation::check_stable(const Energies& e) const {
  const double total = e.kinetic + e.strain;
  if (!std::isfinite(total) || !std::isfinite(e.external_work))
    stop_unstable("energy", std::numeric_limits<double>::quiet_NaN(), 0.0, steps_, time_);
  // Energy created: the shadow energy (conserved by a stable linear run, lowered by fracture)
  // above the budget. Blow-up: the plain energy above twice the budget, which a stable Verlet
  // run never reaches (plain ≤ (1 + (dt/dt_stable)²) · shadow).
  const double allowed = budget_.allowed(e.external_work);
  if (conservative_ && total - e.verlet_correction > allowed)
    stop_unstable("shadow energy (kinetic at the half steps + strain)", total - e.verlet_correction,
                  allowed, steps_, time_);
  const double blow_up = budget_.blow_up(e.external_work, blowup_factor_);
  if (total > blow_up)
    stop_unstable("kinetic + strain energy (blow-up bound)", total, blow_up, steps_, time_);
}

void Simulation::stop_unstable(const char* measured, double energy, double allowed,
                               std::int64_t step, double time) const {
  InstabilityFacts f;
  f.step = step;
  f.time = time;
  f.dt = dt_;
  f.critical_dt = critical_dt_;
  f.non_finite = !std::isfinite(energy);
  f.measured = measured;
  f.energy = energy;
  f.allowed = allowed;
  std::vector<std::int32_t> own(p_.size());
  for (std::size_t i = 0; i < own.size(); ++i) own[i] = bonds_.own_count(i);
  throw InstabilityError(describe_instability(f, p_, particle_dt_, own));
}

Simulation::MemoryUse Simulation::memory_use() const {
  MemoryUse m;
  m.particles = p_.bytes();
  m.bonds = bonds_.bytes();
  for (const auto* v :
       {&C_, &s0_, &particle_dt_, &kinetic_blocks_, &fused_energy_.rows, &kernel_points_.xyzv})
    m.other += v->capacity() * sizeof(double);
  m.other += touched_.capacity();
  if (levels_) m.other += levels_->bytes();
  if (state_) m.other += state_->bytes();
  if (correspondence_) m.other += correspondence_->bytes();
  return m;
}

}  // namespace dhpd
