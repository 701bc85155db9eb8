// Consistent level interfaces (docs/theory.md §14): per-bond stiffness factors that cancel the
// force dual-horizon PD puts on particles near a horizon jump under any homogeneous deformation,
// while every bond force stays a pair of equal and opposite forces (momentum stays exact).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"

namespace dhpd {

/// What one correction did.
struct InterfaceCorrection {
  std::size_t particles = 0;  ///< constrained particles (near a horizon jump, complete horizons)
  std::size_t bonds = 0;      ///< bonds whose factor was solved for
  int iterations = 0;         ///< conjugate-gradient iterations
  double residual = 0.0;      ///< largest remaining |T_p| over the constrained, relative to before
  double smallest = 1.0, largest = 1.0;  ///< range of the factors set
  std::size_t clipped = 0;               ///< factors clipped to [kSmallestFactor, kLargestFactor]
};

/// Bounds on a bond's stiffness factor (the solve asks for more only where levels are mixed
/// cell by cell; compact refined zones measured 0.65–1.40).
inline constexpr double kSmallestFactor = 0.5, kLargestFactor = 2.0;
/// The share of factors that may be clipped before the solve is damped further.
inline constexpr double kClippedShare = 0.01;

/// The factor changes λ of the weakest Tikhonov weight in `dampings` whose λ leave [smallest − 1,
/// largest − 1] for at most kClippedShare of them, else of the last (docs/theory.md §14, §20.6):
/// solve(γ, λ) sets λ and returns its iterations, which are added to `iterations`.
template <class Solve>
std::vector<double> least_damped_changes(std::initializer_list<double> dampings, double smallest,
                                         double largest, Solve&& solve, int& iterations) {
  std::vector<double> lambda;
  for (const double gamma : dampings) {
    iterations += solve(gamma, lambda);
    const auto outside = std::count_if(lambda.begin(), lambda.end(), [&](double l) {
      return l < smallest - 1.0 || l > largest - 1.0;
    });
    if (static_cast<double>(outside) <= kClippedShare * static_cast<double>(lambda.size())) break;
  }
  return lambda;
}

/// 1 + λ clipped to [smallest, largest], counted in `out` (clipped factors, range).
inline double clipped_factor(double lambda, double smallest, double largest,
                             InterfaceCorrection& out) {
  const double factor = std::clamp(1.0 + lambda, smallest, largest);
  out.clipped += factor != 1.0 + lambda ? 1 : 0;
  out.smallest = std::min(out.smallest, factor);
  out.largest = std::max(out.largest, factor);
  return factor;
}

/// Horizons whose ratio reaches this are a jump (refinement levels: 2; a mesh's neighbours: less).
inline constexpr double kHorizonJumpRatio = 1.5;
/// A horizon is complete (no free surface or pre-crack inside it) when the first moment of its
/// volume, |Σ β V_j ξ_j| / (δ Σ β V_j), stays below this: in 2D and 3D 0.15 (0–0.11 measured
/// inside mixed-level lattices, up to 0.56 at a free surface); in 1D, with three neighbours a
/// side, 0.25 (0.2 next to a 2:1 jump, about 0.5 at a free end).
inline double complete_horizon_moment(int dim) {
  return dim == 1 ? 0.25 : 0.15;
}

/// Resets the factors (rows.factor and rows.dilatation_factor, when allocated) of the own bonds
/// with both ends in `region`
/// (sorted particle indices; every particle when empty) to 1 and returns the region's constrained
/// particles, in order: those with a bond (own or dual) across a horizon jump, or bonded to such a
/// particle, whose own horizon and whose partners' horizons are complete (docs/theory.md (14.3)).
std::vector<std::int32_t> reset_interface_region(BondRows& rows, const ParticleStore& p,
                                                 PartialVolume rule,
                                                 const std::vector<std::int32_t>& region);

/// Recomputes the factors φ = 1 + λ (rows.factor, allocated on first use) of the own bonds with
/// both ends in `region` (sorted particle indices; every particle when empty): factors reset to 1,
/// then, over the particles of the region that have a bond (own or dual) across a horizon jump and
/// whose own horizon and whose bond partners' horizons are complete, the smallest factors (in
/// Σ λ_b² K_b) with
///   T_p = Σ_{b ∋ p} K_b (1 + λ_b) V_other n⊗n⊗n = 0     (n from p to the other end)
/// which makes the force on p vanish for every small homogeneous strain. K_b = C_owner β_b. The
/// caller derives the stiffness of the region's rows again.
InterfaceCorrection correct_level_interfaces(BondRows& rows, const ParticleStore& p,
                                             PartialVolume rule,
                                             const std::vector<double>& micromodulus,
                                             const std::vector<std::int32_t>& region);

/// The third moment T_p of particle p's bonds as above (1, 4 or 10 components in 1D, 2D, 3D),
/// with the current factors. Exposed for the tests.
std::vector<double> third_moment(const BondRows& rows, const ParticleStore& p, PartialVolume rule,
                                 const std::vector<double>& micromodulus, std::size_t particle);

}  // namespace dhpd
