// Bond-based DH-PD constants for a constant influence function (docs/theory.md §6; IJNME 2016 eqs.
// 40–43, CMAME 2017 §5). C(δ) is half the classical micromodulus c; s0 from the fracture energy G0.
#pragma once
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/discretization/section.hpp"

namespace dhpd {

struct Material {
  double E = 0.0;    ///< Young's modulus (Pa)
  double rho = 0.0;  ///< density (kg/m³)
  double G0 = 0.0;   ///< fracture energy (J/m²); 0 means "never breaks"
  /// Poisson's ratio of a state-based model; NaN: the value bond-based PD implies.
  double nu = std::numeric_limits<double>::quiet_NaN();
};

/// Poisson's ratio fixed by bond-based PD: 1/4 in 3D, plane strain and 1D; 1/3 in plane stress.
inline double implied_poisson_ratio(const Section& s) {
  return (s.dim == 2 && s.plane == PlaneMode::Stress) ? 1.0 / 3.0 : 0.25;
}

/// The material's Poisson's ratio: its own, or the one bond-based PD implies.
inline double poisson_ratio(const Material& m, const Section& s) {
  return std::isnan(m.nu) ? implied_poisson_ratio(s) : m.nu;
}

/// Bulk modulus κ (of the dimension's dilatation) and shear modulus G of the state-based models
/// (docs/theory.md §20.1): 3D κ = E/(3(1−2ν)); plane strain κ = λ + G = E/(2(1+ν)(1−2ν)); plane
/// stress κ = E/(2(1−ν)); G = E/(2(1+ν)). 1D has one modulus: κ = E, G = E/3, with which the
/// ordinary state-based model is the bond-based one (§20.1).
struct StateModuli {
  double bulk = 0.0, shear = 0.0;
};
inline StateModuli state_moduli(const Material& m, const Section& s) {
  if (s.dim == 1) return {m.E, m.E / 3.0};
  const double nu = poisson_ratio(m, s), shear = m.E / (2.0 * (1.0 + nu));
  if (s.dim == 3) return {m.E / (3.0 * (1.0 - 2.0 * nu)), shear};
  if (s.plane == PlaneMode::Stress) return {m.E / (2.0 * (1.0 - nu)), shear};
  return {m.E / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu)), shear};
}

/// DH-PD micromodulus C(δ) (force per volume² per unit stretch).
inline double micromodulus(const Material& m, const Section& s, double delta) {
  constexpr double pi = std::numbers::pi;
  switch (s.dim) {
    case 1:
      return m.E / (s.area * delta * delta);
    case 2:
      return s.plane == PlaneMode::Stress
                 ? 9.0 * m.E / (2.0 * pi * s.thickness * delta * delta * delta)
                 : 24.0 * m.E / (5.0 * pi * s.thickness * delta * delta * delta);
    default:
      return 6.0 * m.E / (pi * delta * delta * delta * delta);
  }
}

/// Critical stretch s0(δ). 1D is not in the papers; G0 = E s0² δ / 3 follows from the same
/// energy argument (all bonds crossing a section broken), giving s0 = sqrt(3 G0 / (E δ)).
inline double critical_stretch(const Material& m, const Section& s, double delta) {
  constexpr double pi = std::numbers::pi;
  switch (s.dim) {
    case 1:
      return std::sqrt(3.0 * m.G0 / (m.E * delta));
    case 2:
      return s.plane == PlaneMode::Stress ? std::sqrt(4.0 * pi * m.G0 / (9.0 * m.E * delta))
                                          : std::sqrt(5.0 * pi * m.G0 / (12.0 * m.E * delta));
    default:
      return std::sqrt(5.0 * m.G0 / (6.0 * m.E * delta));
  }
}

/// Rayleigh wave speed, IJNME 2016 eq. 60: c_R/c_s = (0.87 + 1.12ν)/(1 + ν), c_s = sqrt(μ/ρ).
inline double rayleigh_speed(const Material& m, const Section& s) {
  const double nu = poisson_ratio(m, s);
  const double mu = m.E / (2.0 * (1.0 + nu));
  return (0.87 + 1.12 * nu) / (1.0 + nu) * std::sqrt(mu / m.rho);
}

}  // namespace dhpd
