// Refinement triggers (docs/theory.md §13.1; IJNME 2016 §5.3): damage, strain-energy density
// relative to the critical energy density, and bond stretch relative to the critical stretch.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/simulation.hpp"

namespace dhpd::refine {

/// Dimensionless thresholds; an absent one is not tested. A particle is triggered when any
/// present one is reached.
struct Triggers {
  std::optional<double> damage;   ///< φ_i ≥ φ*
  std::optional<double> energy;   ///< W_i ≥ w* · W_crit,i
  std::optional<double> stretch;  ///< max over intact own bonds of s ≥ s* · s0_i
  /// The stretch trigger counts only near a crack front: within this many horizons of a
  /// particle damaged to kFrontDamage (counted in that particle's own horizon δ_j, so a refined
  /// tip pulls in a band as narrow as its own horizon), or within near_precrack horizons (δ_i) of
  /// a pre-crack's end or edge inside the body. So a notch tip is refined before its first bond
  /// breaks, but not an impact zone far from any crack.
  std::optional<double> near_crack;
  /// The reach around pre-cracks' fronts, in horizons δ_i of the particle asked; near_crack's
  /// value when absent. A notch starts its crack from the singular field around it, which needs
  /// a wider refined zone before initiation than a running tip does.
  std::optional<double> near_precrack;
  bool any() const { return damage || energy || stretch; }
};

/// Damage that makes a particle part of a running crack's front for `near_crack`.
inline constexpr double kFrontDamage = 0.2;

/// How far the `near_crack` test reaches, in horizons.
struct CrackReach {
  double running;  ///< from a particle j with φ_j ≥ kFrontDamage: |X_i − X_j| ≤ running · δ_j
  double precrack;  ///< from a front of the setup's cracks: distance ≤ precrack · δ_i
};

/// Of the particles marked in `asked`, 1 for those within reach of a crack front (damage as
/// last computed), 0 for the others.
std::vector<std::uint8_t> near_a_crack(const Simulation& sim, CrackReach reach,
                                       std::vector<std::uint8_t> asked);

/// W_crit,i: the DH-PD strain-energy density of particle i when every bond of its horizon is at
/// its critical stretch, Σ_j ½ C_i s0_i² |ξ_ij| β_ij V_j over all its own bonds (broken ones
/// included: the reference horizon). Infinite for a material without G0.
std::vector<double> critical_energy_density(const Simulation& sim);

/// Largest stretch over each particle's intact own bonds (0 when it has none).
std::vector<double> max_bond_stretch(const Simulation& sim);

/// What the refiner adds to the thresholds: its level limit and the particles it need not test.
struct TriggerScope {
  /// A particle k ≥ 1 levels below max_level is tested against stretch^k s0 (docs/theory.md
  /// (13.3)): each split still to go needs its own lead on the crack.
  int max_level = 1;
  /// Flagged particles (settled, refine/settled.hpp) are not tested for stretch.
  const std::vector<std::uint8_t>* skip = nullptr;
  /// The stepper's stretch watch of the current state (Simulation::stretch_watch_hits, limits
  /// from stretch_limits): read instead of a pass over every bond, with the same verdicts.
  const std::vector<std::uint8_t>* stretch_hits = nullptr;
};

/// 1 for every particle that reaches a threshold (damage is recomputed first).
std::vector<std::uint8_t> triggered(const Simulation& sim, const Triggers& t,
                                    const TriggerScope& scope = {});

/// Per particle, the squared stretch ratio (1 + s s0_i)² at which the stretch trigger fires, s
/// the particle's stretch_threshold.
std::vector<double> stretch_limits(const Simulation& sim, double stretch, int max_level);

/// The stretch threshold of a particle at `level` (s* the scene's): s*^k for k = max_level −
/// level ≥ 1 splits still to go, s* itself at or above max_level.
double stretch_threshold(double stretch, int level, int max_level);

}  // namespace dhpd::refine
