// Linear elastic fracture mechanics references for the crack measurements: a semi-infinite crack
// whose faces are loaded suddenly by a pressure p (Freund, Dynamic Fracture Mechanics, 1990,
// §2.5: K_I(t) = 2 p sqrt(c_d t (1 − 2ν) / π) / (1 − ν), plane strain; plane stress by ν →
// ν/(1+ν)).
#pragma once
#include <cmath>
#include <numbers>

#include "engine/physics/material_law.hpp"

namespace dhpd::lefm {

/// Poisson's ratio entering the plane-strain formulas: ν, or ν/(1+ν) in plane stress.
inline double in_plane_poisson_ratio(const Section& s) {
  const double nu = implied_poisson_ratio(s);
  return (s.dim == 2 && s.plane == PlaneMode::Stress) ? nu / (1.0 + nu) : nu;
}

/// Dilatational (P) wave speed of the in-plane problem: sqrt(E / (ρ (1 − ν²))) in plane stress,
/// sqrt(E (1 − ν) / (ρ (1 + ν)(1 − 2ν))) in plane strain and 3D.
inline double dilatational_speed(const Material& m, const Section& s) {
  const double nu = implied_poisson_ratio(s);
  if (s.dim == 2 && s.plane == PlaneMode::Stress) return std::sqrt(m.E / (m.rho * (1.0 - nu * nu)));
  return std::sqrt(m.E * (1.0 - nu) / (m.rho * (1.0 + nu) * (1.0 - 2.0 * nu)));
}

/// Fracture toughness from the fracture energy: K_Ic = sqrt(E' G0), E' = E in plane stress,
/// E / (1 − ν²) in plane strain.
inline double toughness(const Material& m, const Section& s) {
  const double nu = implied_poisson_ratio(s);
  const bool stress = s.dim == 2 && s.plane == PlaneMode::Stress;
  return std::sqrt((stress ? m.E : m.E / (1.0 - nu * nu)) * m.G0);
}

/// K_I a time t after a pressure p was put on the faces of a semi-infinite crack.
inline double suddenly_loaded_crack_K(const Material& m, const Section& s, double p, double t) {
  const double nu = in_plane_poisson_ratio(s);
  return 2.0 * p * std::sqrt(dilatational_speed(m, s) * t * (1.0 - 2.0 * nu) / std::numbers::pi) /
         (1.0 - nu);
}

/// The time after loading at which that K_I reaches the toughness: the crack starts to run.
inline double initiation_delay(const Material& m, const Section& s, double p) {
  const double nu = in_plane_poisson_ratio(s);
  const double k = toughness(m, s);
  return std::numbers::pi * k * k * (1.0 - nu) * (1.0 - nu) /
         (4.0 * p * p * dilatational_speed(m, s) * (1.0 - 2.0 * nu));
}

}  // namespace dhpd::lefm
