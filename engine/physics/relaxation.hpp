// Adaptive dynamic relaxation for statics (docs/theory.md §22; the horizon-size paper §3.2.2,
// eqs. 23–28, with the fictitious density and damping of Kilic & Madenci, Theor. Appl. Fract.
// Mech. 53 (2010) 194, after Underwood 1983): central differences on D ü + c D u̇ = F with a unit
// pseudo-step, D a diagonal fictitious density and c from a Rayleigh quotient of the local
// stiffness, so the iteration is the critically damped motion of the lowest mode.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd {

/// `solver: static` (docs/scenes.md): load steps are time.steps; each ends when the residual
/// force is `tolerance` of the load.
struct StaticSolver {
  double tolerance = 1e-6;               ///< |R| / |load| at which a load step has converged
  std::int64_t max_iterations = 200000;  ///< per relaxation; more is an error (NotConverged)
  /// Per load step: relax, break the bonds beyond their critical stretch, relax again, until
  /// no bond breaks (each round breaks one at least, so this ends) or this many rounds (fracture
  /// only): a crack that runs through a body under a fixed load takes a round per spacing or so.
  int max_break_rounds = 100000;
  /// With fracture: the tolerance of the relaxations between bond breaks (the last one, which
  /// breaks none, is relaxed to `tolerance` and tested again).
  double round_tolerance = 1e-3;
  double safety = 0.9;  ///< fraction of the relaxation's stable pseudo-step (Lanczos on D⁻¹K)
  std::int64_t trace_every = 100;  ///< iterations between samples of the convergence trace
};

/// What a static load step did (Simulation::last_relaxation).
struct RelaxationReport {
  std::int64_t iterations = 0;  ///< ADR iterations, every round
  int rounds = 0;               ///< relaxations (1 + those after bonds broke)
  std::int64_t broken = 0;      ///< bonds broken in the load step
  int edits = 0;                ///< edits between its relaxations (refinement events)
  double residual = 0.0;        ///< |R| / |load| at the end
  double damping = 0.0;         ///< c of the last iteration
  /// (iteration, |R|/|load|, c) every trace_every iterations and at the end of each round.
  struct Sample {
    std::int64_t iteration = 0;
    double residual = 0.0, damping = 0.0;
  };
  std::vector<Sample> trace;
};

/// Per particle, the pseudo-time step τ_i with which the unit pseudo-step of ADR runs (its
/// fictitious density is D_i = ρ_i / τ_i²); `free` marks, per particle and axis (bit a), the
/// components that move.
struct RelaxationState {
  std::vector<double> tau2;        ///< τ_i², s²
  std::vector<double> last_step;   ///< per particle and axis: τ² F/ρ of the previous iteration
  std::vector<std::uint8_t> held;  ///< bit a: axis a prescribed
  double damping = 0.0;            ///< c of the last iteration (per pseudo-step)
};

/// Sums a relaxation iteration needs, over free components (blocked: the same bits for any
/// thread count).
struct ResidualNorms {
  double residual2 = 0.0;  ///< Σ (V F)² over free components (N²)
  double reaction2 = 0.0;  ///< Σ (V F)² over held components: the reactions (N²)
};

/// The residual and reaction norms of the current force density (body forces included).
ResidualNorms residual_norms(const ParticleStore& p, const RelaxationState& s);

/// The damping of Kilic & Madenci's eq. for ADR: c = 2 sqrt(uᵀ K₁ u / uᵀ u) with the diagonal
/// local stiffness K₁,ii = −(Δ(τ²F/ρ))_i / w_i (w the last pseudo-velocity; 0 where w = 0), over
/// free components; 0 when the quotient is not positive, below 2 always (c ≥ 2 would reverse w).
double relaxation_damping(const ParticleStore& p, const RelaxationState& s);

/// Starts a relaxation from rest at the current positions and forces: w^{1/2} = τ²F/(2ρ) (eq. 27
/// with c = 0 and w^{−1/2} = 0), kept in p.velocity, u += w on free components; last_step takes
/// τ²F/ρ.
void relaxation_start(ParticleStore& p, RelaxationState& s);

/// One iteration after a force pass: c from the change of τ²F/ρ, then
/// w^{n+1/2} = ((2 − c) w^{n−1/2} + 2 τ²F/ρ) / (2 + c) (eq. 27), u += w (eq. 28) on free
/// components; positions follow. Returns c.
double relaxation_iteration(ParticleStore& p, RelaxationState& s);

}  // namespace dhpd
