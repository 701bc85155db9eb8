// The bond law of bond-based peridynamics (docs/theory.md §3): stretch, break test, pair force
// factor and pair energy of one bond. The one place these are written: the force, fracture and
// energy loops, the bond rows' stiffness and refine/ all call it.
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

/// The squared stretch ratio (|y|/|ξ|)² from the squared current length and 1/|ξ|, multiplied in
/// this order: the fused break test of the force kernel and every other break decision use these
/// bits, so both rows of a pair decide alike (docs/theory.md §18).
inline double stretch_ratio2(double current_length2, double inverse_length) {
  return current_length2 * inverse_length * inverse_length;
}

/// (1 + s0)²: the squared stretch ratio at which a bond reaches the critical stretch s0.
inline double critical_ratio2(double s0) {
  const double limit = 1.0 + s0;
  return limit * limit;
}

/// Whether a bond has reached the critical stretch s0 (s ≥ s0), compared on squared ratios:
/// (|y|/|ξ|)² ≥ (1 + s0)², no square root. s0 = +∞ (no G0) never breaks.
inline bool reaches_critical_stretch(double ratio2, double s0) {
  return ratio2 >= critical_ratio2(s0);
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
