// What the force model puts on the bond rows (docs/theory.md §4, §18): each entry's pair
// stiffness and each row's break threshold, and the slow path of the fused break test.
// Dual-horizon: an entry of row i carries i's own bond i→j (K = C(δ_i) β_ij φ_ij) and the reaction
// of j's bond j→i (C(δ_j) β_ji φ_ji); the force on i is V_j (K_own μ_own + K_dual μ_dual) s n, so
// both rows of a pair use the same K (the same bits) and the pair's forces are equal and opposite
// to round-off. The classical models use only the own bond, with 2C(δ_i) β_ij.
// K is stored in single precision, scaled by a power of two (BondRows::stiffness_scale): a
// relative change of at most 2⁻²⁴ of each bond's stiffness, the same in both rows, so momentum
// stays exact and energy is conserved (docs/theory.md §18).
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/section.hpp"
#include "engine/physics/bond_law.hpp"

namespace dhpd {

/// What the stiffness and the break tests read: the model, the partial-volume rule, the
/// particles, and the owners' constants.
struct BondConstants {
  ForceModel model;
  PartialVolume rule;
  const ParticleStore& particles;
  const std::vector<double>& micromodulus;  ///< C(δ_i) of particle i's material
  /// s0 of each owner (+∞ without G0); an empty vector: no bond ever breaks.
  const std::vector<double>& critical_stretch;
  /// Multi-horizon model: α of each particle's interaction horizons (multi_horizon.hpp).
  const std::vector<double>& interaction_scale;

  /// Whether bonds owned by i can break (fracture constants, not no_fail).
  bool can_break(std::size_t i) const {
    return !critical_stretch.empty() && !particles.no_fail[i] && std::isfinite(critical_stretch[i]);
  }
  /// (1 + s0_i)²: a bond of i breaks when (|y|/|ξ|)² reaches it.
  double break_ratio2(std::size_t i) const {
    return bond_law::critical_ratio2(critical_stretch[i]);
  }
};

/// K of the bond owner → neighbor with stiffness factor φ (model factor × C_owner β φ), in double.
double bond_stiffness(const BondConstants& c, std::size_t owner, std::size_t neighbor,
                      double length, double factor);

/// K of the bond that `other[k]` owns on particle i (entry k of row i), with its stored factor.
double dual_bond_stiffness(const BondRows& b, const BondConstants& c, std::size_t i,
                           std::int64_t k);

/// The stored stiffness of entry k of row i from its flags: K of the intact bonds the model uses,
/// divided by the rows' scale and rounded to float. Both rows of a pair get the same bits.
float entry_stiffness(const BondRows& b, const BondConstants& c, std::size_t i, std::int64_t k);

/// Sets the stiffness of every entry of row i and the row's break_ratio2.
void refresh_row(BondRows& b, const BondConstants& c, std::size_t i);

/// Every row (in parallel), after choosing the rows' stiffness scale when `choose_scale`.
void refresh_rows(BondRows& b, const BondConstants& c, bool choose_scale);

/// The power of two near the largest micromodulus (1 when there is none): K / scale is of order 1.
double stiffness_scale_for(const std::vector<double>& micromodulus);

/// The slow path of the fused break test, for entry k of row i whose squared stretch ratio
/// (|y|/|ξ|)² = ratio2 reached the row's break_ratio2: breaks each intact bond whose owner can
/// break and whose (1 + s0_owner)² it reaches, then updates the entry's stiffness. Returns the
/// own bonds broken (0 or 1). Writes only entry k of row i.
int break_entry(BondRows& b, std::size_t i, std::int64_t k, double ratio2, const BondConstants& c);

}  // namespace dhpd
