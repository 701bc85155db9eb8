// Instability guard: a non-finite state, or kinetic + strain energy above the energy balance
// E_0 + W_ext + W_map by more than a tolerance of its scale (docs/theory.md §12; explicit Verlet is
// stable only below the stable step, docs/theory.md §9, and grows exponentially above it).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd {

/// What the energy may reach: E_kin + E_strain ≤ initial + external work + mapping + tol · scale.
/// Fracture only dissipates (a broken bond's strain energy is lost), so a stable run stays below.
struct EnergyBudget {
  double tolerance = 0.01;  ///< of `scale`; time.energy_tolerance
  double initial = 0.0;     ///< E_kin + E_strain of the first state
  double mapping = 0.0;     ///< energy added (or removed) by refinement events' state mapping
  double scale = 0.0;       ///< running max of initial + |W_ext| + |mapping|

  /// The scale widened by this external work.
  double scale_with(double external_work) const;
  /// Widens the scale with this external work (call once per step).
  void observe(double external_work);
  /// The energy allowed with this external work.
  double allowed(double external_work) const;
  /// The plain (kinetic + strain) energy a stable run never exceeds: `factor` (2 for velocity
  /// Verlet below its stable step, where plain ≤ (1 + (dt/dt_stable)²) · shadow) times the scale.
  double blow_up(double external_work, double factor) const;
};

/// Kinetic energy summed in fixed blocks of particles (the same bits for any thread count); NaN
/// or Inf when any velocity is not finite. `block_sums` is scratch (resized only when n grows).
double blocked_kinetic_energy(const ParticleStore& p, std::vector<double>& block_sums);

/// Σ ½ ρ V |v|² over the given particles, in their order.
double kinetic_energy_of(const ParticleStore& p, const std::vector<std::int32_t>& particles);

/// What the guard reports when it stops a run.
struct InstabilityFacts {
  std::int64_t step = 0;
  double time = 0.0, dt = 0.0, critical_dt = 0.0;
  bool non_finite = false;
  const char* measured = "energy";  ///< what `energy` is
  double energy = 0.0, allowed = 0.0;
};

/// The message: what happened, where (the particles with non-finite or largest kinetic energy:
/// id, reference position, horizon, bonds, own stable step) and the likely cause.
std::string describe_instability(const InstabilityFacts& f, const ParticleStore& p,
                                 const std::vector<double>& particle_dt,
                                 const std::vector<std::int32_t>& bond_counts);

}  // namespace dhpd
