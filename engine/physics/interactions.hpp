// The per-particle interaction rows that the force kernel gathers over (docs/theory.md §4).
// Row i lists each particle that pushes on i once, in increasing index order. For dual-horizon an
// entry carries two bonds of the pair: i's own bond i→j (coefficient C(δ_i) β_ij V_j) and the
// reaction of j's bond j→i on i (C(δ_j) β_ji V_j); either may be absent when only one horizon
// holds the other particle. The classical models keep only own bonds, with 2C(δ_i) β_ij V_j.
// One stretch evaluation per entry serves both bonds, and the break test shares it: the rows of
// i and j see the same squared length (the same bits) and reach the same decision, each writing
// only its own entries. The kernel streams four arrays (other, 1/|ξ|, the pair's summed
// coefficient, a float break threshold); the bond ids and alive bits are read only when a bond
// may break. Rows are derived from the bond list; `intact` there stays the single truth, which
// the fused kernel updates for the bonds a row owns.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/section.hpp"

namespace dhpd {

/// Break threshold of an entry none of whose bonds can break (absent, broken, no_fail owner, no
/// G0): no squared length compares ≥ NaN, not even +∞.
inline constexpr float kNeverBreaks = std::numeric_limits<float>::quiet_NaN();

/// Bits of InteractionList::alive.
enum AliveBits : std::uint8_t { kOwnAlive = 1, kDualAlive = 2 };

struct InteractionList {
  RowIndex rows;
  std::vector<std::int32_t> other;  ///< the particle at the other end (rows sorted by it)
  std::vector<double> inv_length;   ///< 1/|ξ|
  /// c: K β V_other summed over the entry's intact bonds (0 once both are broken).
  std::vector<double> coefficient;
  /// The smallest ((1 + s0_owner) |ξ|)² of the entry's bonds that can still break, rounded down
  /// to float: |y|² below it breaks nothing; at or above it the exact double test decides.
  std::vector<float> break_at;
  std::vector<BondId> own_bond;     ///< the row particle's bond to `other`, or −1
  std::vector<BondId> dual_bond;    ///< `other`'s bond on the row particle (dual-horizon), or −1
  std::vector<std::uint8_t> alive;  ///< AliveBits of the bonds still intact in this entry
  std::int64_t live = 0;            ///< entries in live rows

  std::size_t size() const { return static_cast<std::size_t>(live); }
  std::int64_t begin(std::size_t i) const { return rows.begin(i); }
  std::int64_t end(std::size_t i) const { return rows.end(i); }
  /// The entry of j in row i (rows are sorted by `other`), or −1 when j does not push on i.
  std::int64_t find(std::size_t i, std::int32_t j) const;
  /// Bytes held by the arrays (capacity, not size: what the allocator gave).
  std::size_t bytes() const;
};

/// What the rows are built from: the model, the bonds, and the owners' constants.
struct RowInputs {
  ForceModel model;
  const BondList& bonds;
  const DualList& dual;
  const ParticleStore& particles;
  const std::vector<double>& micromodulus;  ///< C(δ_i) of particle i's material
  /// s0 of each owner (+∞ without G0); an empty vector builds rows that never break.
  const std::vector<double>& critical_stretch;
};

InteractionList build_interactions(const RowInputs& in);

/// Coefficient of entry k of row i from its bonds and alive bits, with the same operations as a
/// build (so an update after a break matches a rebuild bit for bit).
double entry_coefficient(const InteractionList& il, std::size_t i, std::int64_t k,
                         const RowInputs& in);
/// The entry's break_at from its bonds and alive bits.
float entry_break_at(const InteractionList& il, std::size_t i, std::int64_t k, const RowInputs& in);
/// Sets the entry's coefficient and break_at from its bonds and alive bits (a build, a break and
/// a restore of the alive bits all derive them this way).
inline void refresh_entry(InteractionList& il, std::size_t i, std::int64_t k, const RowInputs& in) {
  il.coefficient[k] = entry_coefficient(il, i, k, in);
  il.break_at[k] = entry_break_at(il, i, k, in);
}

/// The slow path of the fused break test, for an entry whose squared current length l2 reached
/// its break_at: breaks each alive bond with l2 ≥ ((1 + s0_owner)|ξ|)² (marking the own one in
/// `intact`, the bond list's μ), then updates the entry's coefficient and break_at. Returns the
/// own bonds broken (0 or 1). Touches only entry k of row i and the bond row i owns.
int break_entry(InteractionList& il, std::size_t i, std::int64_t k, double l2, const RowInputs& in,
                std::uint8_t* intact);

/// Rewrites row i from its own bonds and dual row (moving it when it has grown).
void rebuild_interaction_row(InteractionList& il, std::size_t i, const RowInputs& in);

}  // namespace dhpd
