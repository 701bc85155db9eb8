// Multi-horizon peridynamics (CMES 2019 §2, eqs. 1–7; docs/theory.md §24): the α of each
// particle's interaction horizons and the pair stiffness of the model, in 1D.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/discretization/section.hpp"

namespace dhpd {

/// Whether particle j belongs to a coarser zone than i (a larger horizon, beyond round-off).
inline bool coarser(const ParticleStore& p, std::size_t j, std::size_t i) {
  return p.horizon[j] > p.horizon[i] * (1.0 + 1e-9);
}

/// The side of i that j lies on: 1 toward +x, 0 toward −x (1D).
inline std::size_t side_of(const ParticleStore& p, std::size_t i, std::size_t j) {
  return p.reference_position[0][j] > p.reference_position[0][i] ? 1 : 0;
}

/// Calls visit(i, side, r0, r1) for each particle j coarser than i whose cell reaches into i's
/// natural horizon: the part of the cell inside it spans distances r0 < r1 from x_i (1D).
using CoarserOverlap = std::function<void(std::size_t, std::size_t, double, double)>;
void for_each_coarser_overlap(const ParticleStore& p, const CoarserOverlap& visit);

/// α of particle i's interaction horizon on each side, at 2i + side: the coarser particles that
/// include i (their own bond on i) form it, and eq. 7 for a uniform stretch fixes α so that their
/// pair integrand, (C_i + C_j) per volume, carries what the refined material would in the part
/// of i's natural horizon that coarser particles occupy, 2 C_i per volume:
///   α = 2 C_i |H ∩ coarser cells| / Σ_j (C_i + C_j) ℓ_j   (0 where no coarser cell is there).
/// Throws MultiHorizonError (an InputError) outside 1D, when no particle has an interaction horizon
/// (no refinement zone), and when coarser material lies in a particle's horizon but none of it
/// includes the particle (α undefined).
std::vector<double> interaction_scales(const BondRows& b, const ParticleStore& p,
                                       const std::vector<double>& micromodulus);

/// K of entry k of row i under the multi-horizon model (before the rows' stiffness scale): the
/// pair integrand (T − T′) of eq. 3, T = C β s for a natural bond and α C s for an interaction
/// bond; `alpha` from interaction_scales.
double multi_horizon_stiffness(const BondRows& b, const ParticleStore& p, PartialVolume rule,
                               const std::vector<double>& micromodulus,
                               const std::vector<double>& alpha, std::size_t i, std::int64_t k);

}  // namespace dhpd
