// Bonds stored in rows, one per particle: the one bond store of a run (docs/theory.md §2, §4, §18).
// Row i lists, once each and in increasing index, every particle j that i shares a bond with in
// either direction: i's own bond i→j (j ∈ H_i, owner i) and/or the dual bond j→i (i ∈ H_j, owner
// j). Bond i→j exists for every j with β_ij > 0 whose reference segment crosses no crack: j in H_i
// for none/linear, up to δ_i + r_j for exact (a particle partly inside the horizon). The own bond
// of row i's entry j is the dual bond of row j's entry i: both rows hold its intact state and
// reach the same decision from the same bits, so a row is only ever written by its own thread.
// Per entry the store keeps what cannot be derived cheaply: the other particle, the index of 1/|ξ|
// in the table of distinct lengths (engine/discretization/length_table.hpp), the flags, the pair
// stiffness of the entry's intact bonds (single precision, engine/physics/interactions) and, near
// level interfaces, the own bond's stiffness factor; β is recomputed where needed.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "engine/discretization/row_arena.hpp"
#include "engine/discretization/section.hpp"
#include "geometry/crack.hpp"

namespace dhpd {

/// Bits of BondRows::flags: which bonds of the pair exist and which are still intact (μ = 1).
enum BondFlags : std::uint8_t { kOwn = 1, kDual = 2, kOwnIntact = 4, kDualIntact = 8 };

struct BondRows {
  RowIndex rows;
  std::vector<std::int32_t> other;  ///< the particle at the other end (rows sorted by it)
  /// Index of the entry's 1/|ξ| in `inverse_lengths` (the same value in both rows of a pair).
  std::vector<std::int32_t> length_index;
  /// The distinct values of 1/|ξ| (length_table.hpp; canonical after a build or renumbering).
  std::vector<double> inverse_lengths;
  std::vector<std::uint8_t> flags;  ///< BondFlags
  /// φ_ij = 1 + λ of the own bond (engine/physics/interface_consistency.hpp); empty while every
  /// factor is 1 (no level interface has been corrected).
  std::vector<float> factor;
  /// ψ_ij = 1 + ν of the own bond's dilatation weight (ordinary state-based family only:
  /// engine/physics/state_interfaces.hpp); empty while every one is 1.
  std::vector<float> dilatation_factor;
  /// K of the entry's intact bonds divided by `stiffness_scale`, without the other's volume: for
  /// dual-horizon C_i β_ij φ_ij μ_ij + C_j β_ji φ_ji μ_ji, the same bits in both rows of a pair
  /// (engine/physics/interactions.hpp). 0 once both are broken.
  std::vector<float> stiffness;
  /// A power of two fixed when the rows are built, so that stiffness stays well inside the range
  /// of a float for any micromodulus: K = stiffness × stiffness_scale exactly.
  double stiffness_scale = 1.0;
  /// Per row: the smallest (1 + s0)² of the row's bonds that can break (+∞ for none). A squared
  /// stretch ratio below it breaks nothing in the row (the kernel's fast test).
  std::vector<double> break_ratio2;
  std::int64_t live = 0;       ///< entries in live rows
  std::int64_t own_bonds = 0;  ///< own bonds in live rows: the directed bonds of the run

  /// Bonds in live rows (own bonds: each directed bond once).
  std::size_t bond_count() const { return static_cast<std::size_t>(own_bonds); }
  std::size_t particles() const { return rows.rows(); }
  std::int64_t begin(std::size_t i) const { return rows.begin(i); }
  std::int64_t end(std::size_t i) const { return rows.end(i); }
  bool has_own(std::int64_t k) const { return flags[k] & kOwn; }
  bool has_dual(std::int64_t k) const { return flags[k] & kDual; }
  bool own_intact(std::int64_t k) const { return flags[k] & kOwnIntact; }
  bool dual_intact(std::int64_t k) const { return flags[k] & kDualIntact; }
  /// 1/|ξ| of entry k.
  double inverse_length(std::int64_t k) const {
    return inverse_lengths[static_cast<std::size_t>(length_index[k])];
  }
  /// |ξ| of entry k (every loop derives it this way, so it has the same bits everywhere).
  double length(std::int64_t k) const { return 1.0 / inverse_length(k); }
  /// φ of the own bond of entry k (1 while no factor is stored).
  double own_factor(std::int64_t k) const { return factor.empty() ? 1.0 : factor[k]; }
  double own_dilatation_factor(std::int64_t k) const {
    return dilatation_factor.empty() ? 1.0 : dilatation_factor[k];
  }
  /// The entry of j in row i (rows are sorted by `other`), or −1.
  std::int64_t find(std::size_t i, std::int32_t j) const;
  /// Own bonds of row i.
  std::int32_t own_count(std::size_t i) const;
  /// Resizes the entry arrays to the arena (new slots are empty: other −1, no flags). An array
  /// that must grow takes half as much again (doubling would hold up to twice the arena; an
  /// eighth copied the arrays every second event of the 3D adaptive plate, 8 % slower).
  void fit_arena();
  /// Bytes held by the arrays (capacities: what the allocator gave).
  std::size_t bytes() const;
};

/// Calls f(k, j) for every own bond of particle i: entry k of row i, neighbour j.
template <class F>
void for_each_own_bond(const BondRows& b, std::size_t i, F&& f) {
  for (auto k = b.begin(i); k < b.end(i); ++k)
    if (b.flags[k] & kOwn) f(k, static_cast<std::size_t>(b.other[k]));
}

/// Relative tolerance of the horizon test |ξ| ≤ δ (1 + tol) of the none and linear rules: a
/// neighbour at δ up to round-off is inside.
inline constexpr double kHorizonTieTolerance = 1e-10;

/// Partial-volume factor β for a neighbour at distance `distance` with radius r_j (docs/theory.md
/// §7): r_j = Δx_j/2 for linear, the equal-measure radius for exact; unused by none.
double partial_volume_factor(PartialVolume rule, int dim, double distance, double horizon,
                             double r_j);

/// β of the bond owner → neighbour at reference length `length` (the store's radius or half
/// spacing of the neighbour, the owner's horizon).
double bond_weight(const ParticleStore& p, PartialVolume rule, std::size_t owner,
                   std::size_t neighbor, double length);

/// Fills p.radius with each particle's equal-measure radius (Section::equal_measure_radius).
void set_particle_radii(ParticleStore& p, const Section& section);

/// The rows of every particle from the reference positions, horizons and spacings (and, for
/// exact partial volumes, the radii: every radius must be > 0), all bonds intact. Stiffness and
/// break thresholds are left for engine/physics/interactions to fill. Built in two passes over
/// the own bonds without a second copy of them; the same rows for any thread count.
BondRows build_bond_rows(const ParticleStore& particles, PartialVolume rule,
                         const std::vector<geometry::Crack>& cracks);

/// The rows after the particles are renumbered (order[k]: old index of new particle k, new_index
/// its inverse), packed without spare room in any row, each row sorted by its new `other`; every
/// entry keeps its length, flags, factor and stiffness; the length table is made canonical. The
/// entry arrays hold `spare` × the entries more in capacity (for the rows the next refinement
/// events move to the end of the arena, without copying the arrays again).
BondRows renumbered_rows(const BondRows& rows, const std::vector<std::int32_t>& order,
                         const std::vector<std::int32_t>& new_index, double spare = 0.0);

/// The rows after the particles are renumbered in place by `order` (order[k]: the particle that
/// goes to slot k; new_index its inverse), where it moves only the slots `moved` (ascending;
/// order[k] = k elsewhere): the moved rows keep their place in the arena, the rows naming a moved
/// particle are re-sorted; nothing else is touched. Returns those rows (the moved ones and their
/// partners, ascending), whose sums over entries are to be derived again.
std::vector<std::int32_t> renumber_rows_in_place(BondRows& rows,
                                                 const std::vector<std::int32_t>& order,
                                                 const std::vector<std::int32_t>& new_index,
                                                 const std::vector<std::int32_t>& moved);

/// One own bond to write: neighbour and intact state.
struct NewBond {
  std::int32_t neighbor;
  bool intact;
};

/// Replaces the own bonds of the `owners` (ascending) by `bonds[k]` for owners[k] (each sorted by
/// neighbour), and the dual side of those bonds in the neighbours' rows; entries left with no bond
/// go. Lengths come from the reference positions. Returns every row that changed, ascending; their
/// stiffness and break thresholds must be derived again. (The incremental rebuild of refine/.)
std::vector<std::int32_t> replace_own_bonds(BondRows& rows, const ParticleStore& p,
                                            const std::vector<std::int32_t>& owners,
                                            const std::vector<std::vector<NewBond>>& bonds);

/// The own bonds particle i would get from scratch, found with `search_within(i, radius, out)`
/// (sorted candidate indices).
struct BondRowBuilder {
  /// `reach`: how far past δ_i a neighbour can still overlap i's horizon (an upper bound on the
  /// radii for exact partial volumes, see exact_reach; 0 otherwise).
  BondRowBuilder(const ParticleStore& particles, PartialVolume rule,
                 const std::vector<geometry::Crack>& cracks, double reach);
  /// The largest particle radius (exact partial volumes; throws when a radius is not > 0), else 0.
  static double exact_reach(const ParticleStore& particles, PartialVolume rule);
  /// Radius to search around i so that every j with β_ij > 0 is found.
  double search_radius(std::size_t i) const;
  /// Keeps the candidates of `cand` that become bonds of i (in order).
  void keep_bonds(std::size_t i, std::vector<std::int32_t>& cand) const;
  /// Whether i has a bond to j (β_ij > 0 at the rows' length, no crack between them).
  bool bonded(std::size_t i, std::size_t j) const;
  /// Given that i has a bond to j, whether j has one to i: the crack test is the pair's, so only
  /// β_ji is left to ask.
  bool bonded_back(std::size_t i, std::size_t j) const;

 private:
  const ParticleStore& p_;
  PartialVolume pv_;
  double reach_ = 0.0;
  const std::vector<geometry::Crack>& cracks_;
  /// Each crack's bounding box: a pair whose segment's box misses it cannot cross the crack.
  std::vector<std::pair<geometry::Vec3, geometry::Vec3>> crack_boxes_;
};

/// 1/|ξ| of the pair (i, j) from the reference positions, the same bits for (j, i).
double inverse_reference_length(const ParticleStore& p, std::size_t i, std::size_t j);

}  // namespace dhpd
