// The bond law of bond-based peridynamics (docs/theory.md §3): stretch, break test, pair force
// factor and pair energy of one bond. The one place these are written: the force, fracture and
// energy loops, the interaction rows and refine/ all call it.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "engine/discretization/particles.hpp"

namespace dhpd::bond_law {

/// |y_j − y_i|² in the current configuration, components summed in axis order (the bits every
/// loop shares).
template <int Dim>
inline double squared_length(const double* const y[3], std::size_t i, std::size_t j) {
  double l2 = 0.0;
  for (int a = 0; a < Dim; ++a) {
    const double d = y[a][j] - y[a][i];
    l2 += d * d;
  }
  return l2;
}

/// The same for a store of any dimension.
inline double squared_length(const ParticleStore& p, std::size_t i, std::size_t j) {
  double l2 = 0.0;
  for (int a = 0; a < p.dim(); ++a) {
    const double d = p.position[a][j] - p.position[a][i];
    l2 += d * d;
  }
  return l2;
}

/// Stretch s = |y|/|ξ| − 1 from the squared current length and the reference length |ξ|
/// (docs/theory.md eq. 3.1).
inline double stretch(double current_length2, double length) {
  return std::sqrt(current_length2) / length - 1.0;
}

/// The squared current length at which a bond of reference length |ξ| reaches the critical
/// stretch s0: ((1 + s0) |ξ|)² (the interaction rows store it per bond).
inline double critical_length2(double length, double s0) {
  const double limit = (1.0 + s0) * length;
  return limit * limit;
}

/// Whether a bond has reached the critical stretch s0 (s ≥ s0), compared on squared lengths:
/// |y|² ≥ ((1 + s0) |ξ|)², no square root. s0 = +∞ (no G0) never breaks.
inline bool reaches_critical_stretch(double current_length2, double length, double s0) {
  return current_length2 >= critical_length2(length, s0);
}

/// The coefficient c of a bond in an interaction row: force density per unit stretch on the row's
/// particle, c = m C β φ V_other μ, with m = 1 for an own or dual bond of DH-PD and 2 for the
/// classical model's own bond, C the owner's micromodulus, β the partial volume, φ the
/// level-interface factor, μ = 1 intact, 0 broken (docs/theory.md §4).
inline double coefficient(double model_factor, double owner_micromodulus, double weight,
                          double stiffness, double other_volume, std::uint8_t intact) {
  return model_factor * owner_micromodulus * weight * stiffness * other_volume * intact;
}

/// The pair force of a row entry as a multiple of y_j − y_i: c s n = c (1/|ξ| − 1/|y|) (y_j − y_i).
inline double force_factor(double coefficient, double inverse_length, double current_length2) {
  return coefficient * (inverse_length - 1.0 / std::sqrt(current_length2));
}

/// One bond's share of its owner's strain-energy density before the factor ½ C_owner:
/// s² |ξ| β φ V_j (docs/theory.md §3), so W_i = ½ C_i Σ_j s² |ξ| β φ V_j.
inline double energy_share(double s, double length, double weight, double stiffness,
                           double other_volume) {
  return s * s * length * weight * stiffness * other_volume;
}

}  // namespace dhpd::bond_law
