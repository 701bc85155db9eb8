// Statics by adaptive dynamic relaxation (docs/theory.md §22): each step() is a load step at load
// factor k / load_steps, relaxed until the residual force is the solver's tolerance of the load;
// with fracture, bonds beyond their critical stretch break between relaxations.
#include <fmt/core.h>
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/stable_step.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

double Simulation::load_factor() const {
  if (!setup_.statics) return 1.0;
  return static_cast<double>(steps_ + (solving_load_step_ ? 1 : 0)) /
         static_cast<double>(setup_.load_steps);
}

std::vector<double> Simulation::relaxation_steps() const {
  // D_i = ρ_i / dt_i² with dt_i the particle's own bound (9.1) (the bond-based one of the same E
  // for the state-based families, a guide to its local stiffness): the largest eigenvalue of
  // D⁻¹K by Lanczos gives the stable pseudo-step ĥ, and τ_i = safety · ĥ · dt_i (§22).
  double largest = 0.0;
  for (const double t : particle_dt_)
    if (std::isfinite(t)) largest = std::max(largest, t);
  std::vector<double> dt(particle_dt_);
  for (auto& t : dt)
    if (!std::isfinite(t)) t = largest;
  ParticleStore scaled = p_;
  for (std::size_t i = 0; i < p_.size(); ++i) scaled.density[i] = p_.density[i] / (dt[i] * dt[i]);
  const double pseudo = state_based() ? state_lanczos_dt(scaled)
                                      : lanczos_stable_step(bonds_, scaled, 80, 1e-4, nullptr).dt;
  const double h = setup_.statics->safety * pseudo;
  std::vector<double> tau2(p_.size());
  for (std::size_t i = 0; i < p_.size(); ++i) tau2[i] = h * h * dt[i] * dt[i];
  return tau2;
}

double Simulation::applied_load2() const {
  const double lambda = load_factor();
  double sum = 0.0;
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k) {
    const double v = p_.volume[static_cast<std::size_t>(loads_.loaded[k])];
    for (int a = 0; a < p_.dim(); ++a) sum += std::pow(lambda * v * loads_.body_force[k][a], 2);
  }
  return sum;
}

std::int64_t Simulation::relax(RelaxationState& state, double tolerance, double floor) {
  const auto& solver = *setup_.statics;
  auto& report = relaxation_report_;
  double first = 0.0;  // the first residual, the reference when nothing is loaded
  const double applied = applied_load2();  // the body forces' part: fixed within a load step
  const auto measure = [&](std::int64_t iteration, bool sample) {
    // The load now: body forces and the reactions of the held components as they are (at the
    // start of a load step these are far from their final values), but not below the largest
    // an equilibrium carried (`floor`: a body a crack has parted carries almost nothing, and its
    // residual cannot fall below round-off of the forces it carried).
    const auto norms = residual_norms(p_, state);
    if (iteration == 0) first = std::sqrt(norms.residual2);
    const double load = std::max(std::sqrt(applied + norms.reaction2), floor);
    const double reference = load > 0.0 ? load : first;
    const double ratio = reference > 0.0 ? std::sqrt(norms.residual2) / reference : 0.0;
    if (!std::isfinite(ratio))
      stop_unstable("residual force of the relaxation", std::numeric_limits<double>::quiet_NaN(),
                    0.0, steps_ + 1, load_factor());
    report.residual = ratio;
    report.damping = state.damping;
    if (sample) report.trace.push_back({report.iterations + iteration, ratio, state.damping});
    return ratio;
  };
  apply_layers();
  compute_forces();
  std::int64_t it = 0;
  if (measure(0, true) <= tolerance) return 0;
  relaxation_start(p_, state);
  for (it = 1; it <= solver.max_iterations; ++it) {
    apply_layers();
    compute_forces();
    const bool sample = solver.trace_every > 0 && it % solver.trace_every == 0;
    if (measure(it, sample) <= tolerance) break;
    relaxation_iteration(p_, state);
  }
  if (it > solver.max_iterations)
    throw InstabilityError(fmt::format(
        "the static solver did not converge in load step {} (load factor {:.6g}): after {} "
        "iterations the residual force is {:.3g} of the load, the tolerance {:.3g} (raise "
        "solver.max_iterations, or check that every part of the body is held: a free rigid-body "
        "motion never settles)",
        steps_ + 1, load_factor(), solver.max_iterations, report.residual, tolerance));
  if (solver.trace_every == 0 || it % solver.trace_every != 0)
    report.trace.push_back({report.iterations + it, report.residual, state.damping});
  return it;
}

Simulation::WorkBaseline Simulation::work_baseline() const {
  WorkBaseline w;
  const int dim = p_.dim();
  w.loaded.resize(static_cast<std::size_t>(dim) * loads_.loaded.size());
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k)
    for (int a = 0; a < dim; ++a)
      w.loaded[dim * k + a] = p_.displacement[a][static_cast<std::size_t>(loads_.loaded[k])];
  w.held = held_state(0);
  return w;
}

double Simulation::work_since(const WorkBaseline& w, double factor) const {
  // The body forces' work at `factor` (the load step's mean load factor for the segment that
  // changes the load: trapezoidal, exact for a linear response), and the held components'.
  const int dim = p_.dim();
  double work = 0.0;
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k) {
    const auto i = static_cast<std::size_t>(loads_.loaded[k]);
    for (int a = 0; a < dim; ++a)
      work += factor * loads_.body_force[k][a] * (p_.displacement[a][i] - w.loaded[dim * k + a]) *
              p_.volume[i];
  }
  return work + held_work(w.held);
}

void Simulation::prepare_relaxation(RelaxationState& state) const {
  state.tau2 = relaxation_steps();
  state.held = prescribed_axes(loads_, p_.size());
}

double Simulation::static_step(const StepExtras& extras) {
  // What the caller hands a step: run here, before the load step changes the state.
  if (extras.before_change) (*extras.before_change)(0, static_cast<std::int64_t>(p_.size()));
  if (extras.side_task) (*extras.side_task)();
  solving_load_step_ = true;
  const struct Done {
    bool& flag;
    ~Done() { flag = false; }
  } done{solving_load_step_};
  relaxation_report_ = {};
  StaticWork work{work_baseline(), 0.0};  // from the last equilibrium
  const double lambda = load_factor();
  RelaxationState state;
  apply_prescribed_displacement(loads_, setup_.boundary_conditions, lambda, lambda, p_);
  prepare_relaxation(state);
  // The load changed from λ − 1/N to λ over the step: its body forces' work is trapezoidal.
  const double mean = lambda - 0.5 / static_cast<double>(setup_.load_steps);
  relax_and_break(state, extras.between_relaxations, work, mean);
  for (int a = 0; a < p_.dim(); ++a) std::fill(p_.velocity[a].begin(), p_.velocity[a].end(), 0.0);
  apply_layers();
  compute_forces();
  load_scale_ =
      std::max(load_scale_, std::sqrt(applied_load2() + residual_norms(p_, state).reaction2));
  return work.done + work_since(work.since, mean);
}

void Simulation::relax_and_break(RelaxationState& state, const EditTask* edit, StaticWork& work,
                                 double mean) {
  auto& report = relaxation_report_;
  const auto& solver = *setup_.statics;
  const double lambda = load_factor();
  const double floor = load_scale_;
  // With fracture, the rounds that only find the next bonds to break relax to the looser
  // round_tolerance; the state a round leaves unbroken is relaxed to the tolerance and tested
  // again. An edit (a refinement event) comes before any bond breaks: the edited state is relaxed
  // again first, so bonds break on the discretisation the triggers asked for (§22, refinement
  // between relaxations).
  const double loose = std::max(solver.tolerance, solver.round_tolerance);
  double tolerance = setup_.effects.fracture || edit ? loose : solver.tolerance;
  for (report.rounds = 1;; ++report.rounds) {
    report.iterations += relax(state, tolerance, floor);
    const bool edited = edit && edit_between_relaxations(*edit, work, mean);
    const auto before = broken_;
    if (edited) {
      ++report.edits;
      prepare_relaxation(state);
    } else if (setup_.effects.fracture) {
      broken_ += break_bonds(bonds_, p_, bond_constants());
      report.broken += broken_ - before;
    }
    if (!edited && broken_ == before) {
      if (tolerance == solver.tolerance) return;
      tolerance = solver.tolerance;
      continue;
    }
    tolerance = loose;
    if (!edited) {
      // The broken bonds made their particles softer: each takes its new stable pseudo-step, so
      // a particle left hanging by a few bonds is not overdamped into a stall.
      particle_time_steps(bonds_, p_, particle_dt_);
      prepare_relaxation(state);
    }
    if (report.rounds == solver.max_break_rounds)
      throw InstabilityError(fmt::format(
          "bonds still broke after {} relaxations in load step {} (load factor {:.6g}; {} bonds "
          "broke in it, {} refinement events): the crack grows unstably at this load (take more "
          "load steps, or raise solver.max_break_rounds)",
          report.rounds, steps_ + 1, lambda, report.broken, report.edits));
  }
}

bool Simulation::edit_between_relaxations(const EditTask& edit, StaticWork& work, double mean) {
  // The work up to the edit is booked first: the edit renumbers what the baseline indexes.
  const double segment = work_since(work.since, mean);
  if (!edit()) return false;
  work.done += segment;
  work.since = work_baseline();
  // Children of held particles take the prescribed displacement exactly (the mapping gives them
  // their parent's field, which differs from it by the field's gradient): the work of that last
  // move is booked with the load step's (the baseline is from before it).
  const double lambda = load_factor();
  apply_prescribed_displacement(loads_, setup_.boundary_conditions, lambda, lambda, p_);
  apply_layers();
  compute_forces();
  return true;
}

}  // namespace dhpd
