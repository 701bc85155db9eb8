// Bond-based DH-PD constants for a constant influence function (docs/theory.md §6; IJNME 2016 eqs.
// 40–43, CMAME 2017 §5). C(δ) is half the classical micromodulus c; s0 from the fracture energy G0.
#pragma once
#include <cmath>
#include <numbers>

#include "engine/discretization/section.hpp"

namespace dhpd {

struct Material {
  double E = 0.0;    ///< Young's modulus (Pa)
  double rho = 0.0;  ///< density (kg/m³)
  double G0 = 0.0;   ///< fracture energy (J/m²); 0 means "never breaks"
};

/// Poisson's ratio fixed by bond-based PD: 1/4 in 3D, plane strain and 1D; 1/3 in plane stress.
inline double implied_poisson_ratio(const Section& s) {
  return (s.dim == 2 && s.plane == PlaneMode::Stress) ? 1.0 / 3.0 : 0.25;
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
  const double nu = implied_poisson_ratio(s);
  const double mu = m.E / (2.0 * (1.0 + nu));
  return (0.87 + 1.12 * nu) / (1.0 + nu) * std::sqrt(mu / m.rho);
}

}  // namespace dhpd
