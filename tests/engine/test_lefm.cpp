// The LEFM reference of the crack tests (tests/support/lefm.hpp: Freund's suddenly loaded
// semi-infinite crack, Dynamic Fracture Mechanics, 1990, §2.5) against numbers worked by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/lefm.hpp"

namespace {

const dhpd::Material kGlass{72.0e9, 2440.0, 135.0};  // cases/branching_plate_uniform.yaml
const dhpd::Section kPlaneStress{2, dhpd::PlaneMode::Stress, 0.001, 1.0};

TEST(Lefm, FreundReferenceNumbers) {
  // By hand: c_d = sqrt(72e9 / (2440 · 8/9)) = 5761.66 m/s; K_Ic = sqrt(72e9 · 135) = 3.1177 MPa√m;
  // ν̄ = 1/4; τ = π K² (3/4)² / (4 p² c_d / 2) = 2.588 µs for p = 24 MPa.
  EXPECT_NEAR(dhpd::lefm::dilatational_speed(kGlass, kPlaneStress), 5761.66, 0.01);
  EXPECT_NEAR(dhpd::lefm::toughness(kGlass, kPlaneStress), 3.1177e6, 1e2);
  const double tau = dhpd::lefm::initiation_delay(kGlass, kPlaneStress, 24e6);
  EXPECT_NEAR(tau, 2.588e-6, 1e-9);
  EXPECT_NEAR(dhpd::lefm::suddenly_loaded_crack_K(kGlass, kPlaneStress, 24e6, tau),
              dhpd::lefm::toughness(kGlass, kPlaneStress), 1e-6);
  // K ∝ p √t: twice the pressure, a quarter of the time.
  EXPECT_NEAR(dhpd::lefm::initiation_delay(kGlass, kPlaneStress, 48e6), tau / 4, 1e-15);
  // Plane strain (ν = 1/4): c_d = sqrt(E · 0.75 / (ρ · 1.25 · 0.5)), E' = E / (1 − 1/16).
  const dhpd::Section strain{2, dhpd::PlaneMode::Strain, 0.001, 1.0};
  EXPECT_NEAR(dhpd::lefm::dilatational_speed(kGlass, strain), std::sqrt(72e9 * 1.2 / 2440), 1e-9);
  EXPECT_NEAR(dhpd::lefm::toughness(kGlass, strain), std::sqrt(72e9 * 135 * 16 / 15), 1e-6);
}

}  // namespace
