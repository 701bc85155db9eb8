// The per-particle interaction rows that the force kernel gathers over (docs/theory.md §4).
// Row i lists every bond that pushes on i: for dual-horizon its own bonds (coefficient C(δ_i) β_ij
// V_j) followed by its dual bonds (C(δ_j) β_ji V_j); for the classical models only its own bonds
// with 2C(δ_i) β_ij V_j. The kernel is the same loop for every model: the model only decides the
// rows. Rows are derived from the bond list; `intact` in the bond list stays the single truth, and
// the break pass zeroes the coefficient of both views of a broken bond.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/section.hpp"

namespace dhpd {

struct InteractionList {
  RowIndex rows;
  std::vector<std::int32_t> other;      ///< the particle at the other end
  std::vector<double> inv_length;       ///< 1/|ξ|
  std::vector<double> coefficient;      ///< K β V_other, zero once the bond is broken
  std::vector<std::int64_t> own_slot;   ///< per bond slot: its entry in the owner's row
  std::vector<std::int64_t> dual_slot;  ///< per bond slot: its entry in the neighbour's row, or −1
  std::int64_t live = 0;                ///< entries in live rows

  std::size_t size() const { return static_cast<std::size_t>(live); }
  std::int64_t begin(std::size_t i) const { return rows.begin(i); }
  std::int64_t end(std::size_t i) const { return rows.end(i); }
};

/// `micromodulus[i]` is C(δ_i) of particle i's material.
InteractionList build_interactions(ForceModel model, const BondList& bonds, const DualList& dual,
                                   const ParticleStore& particles,
                                   const std::vector<double>& micromodulus);

/// Rewrites row i from its own bonds and dual row (moving it when it has grown), and points
/// own_slot / dual_slot of those bonds at it. The slot maps must already cover bonds.slots().
void rebuild_interaction_row(InteractionList& il, std::size_t i, ForceModel model,
                             const BondList& bonds, const DualList& dual,
                             const ParticleStore& particles,
                             const std::vector<double>& micromodulus);

}  // namespace dhpd
