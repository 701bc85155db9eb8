// Consistent level interfaces for the ordinary state-based family (docs/theory.md §20.6): factors
// on the bonds' deviatoric weights near a horizon jump that cancel the force a homogeneous strain
// leaves there, keeping the model the gradient of an energy and every bond a pair of equal and
// opposite forces.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/physics/interface_consistency.hpp"
#include "engine/physics/ordinary_state.hpp"

namespace dhpd {

/// Bounds on the state-based factors φ and ψ: any positive factor keeps the energy (20.7) a sum
/// of squares; the solve asks for up to 0.35–2.4 at a compact 2D zone (docs/theory.md §20.6).
inline constexpr double kSmallestStateFactor = 0.25, kLargestStateFactor = 4.0;

/// Recomputes the factors φ = 1 + λ (rows.factor, allocated on first use) of the own bonds with
/// both ends in `region` (sorted particle indices; every particle when empty) for the ordinary
/// state-based model `in` describes: factors reset to 1, then, over the constrained particles of
/// the region (reset_interface_region), the smallest factors in Σ_b W_b λ_b² (W_b = V_o g w Q_o
/// |ξ|², the bond's deviatoric stiffness) with
///   F_p(ε) = 0 for every homogeneous strain ε at constrained p, unchanged at the other particles
///   whose forces the factors reach (the owners' bond partners, through the owners' S and α),
/// F_p the linearised state-based force on p (all bonds counted, broken or not). The net force and
/// moment of each connected group cannot change (every bond is a central pair): that part is left.
/// With `built`, it receives the state model of the rows with the new factors (the same bits as
/// building it again from them), else the caller builds it.
InterfaceCorrection correct_state_interfaces(BondRows& rows, const ParticleStore& p,
                                             const OrdinaryStateInputs& in,
                                             const std::vector<std::int32_t>& region,
                                             std::optional<OrdinaryState>* built = nullptr);

/// F_p(ε) of every particle for each unit strain ε^q (q: xx, yy, xy in 2D; xx, yy, zz, xy, xz, yz
/// in 3D; ε_ab = ε_ba = ½ off the diagonal), dim values per strain: out[(p·c + q)·dim + a], with
/// the model's current weights and every bond counted. Exposed for the tests.
std::vector<double> state_strain_forces(const BondRows& rows, const ParticleStore& p,
                                        const OrdinaryState& model);

}  // namespace dhpd
