// Bonds in flat CSR per owner plus the dual-horizon lists (docs/theory.md §2, §7, §8).
// Bond b (owner i, neighbour j) is created for every j with β_ij > 0 whose reference segment
// crosses no crack: j in H_i for none/linear, and up to δ_i + r_j for exact (a particle partly
// inside the horizon). The dual list of j holds the ids of the bonds others own on j.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "engine/discretization/row_arena.hpp"
#include "engine/discretization/section.hpp"
#include "geometry/crack.hpp"

namespace dhpd {

using BondId = std::int32_t;

/// A bond's id is its slot in the arena. Slots outside every live row are garbage (owner and
/// neighbour −1) until compaction.
struct BondList {
  RowIndex rows;                    ///< own bonds of particle i: [rows.begin(i), rows.end(i))
  std::vector<std::int32_t> owner;  ///< owner of each slot (O(1) lookup from a bond id)
  std::vector<std::int32_t> neighbor;
  std::vector<double> length;        ///< |ξ| in the reference configuration
  std::vector<double> weight;        ///< partial-volume factor β_ij
  std::vector<std::uint8_t> intact;  ///< μ_ij: 1 until the bond breaks, never healed
  /// 1 + λ_b: the factor on the bond's stiffness that makes level interfaces consistent
  /// (engine/interface_consistency.hpp); 1 away from horizon jumps.
  std::vector<double> stiffness;
  std::int64_t live = 0;  ///< bonds in live rows

  std::size_t size() const { return static_cast<std::size_t>(live); }
  std::size_t slots() const { return neighbor.size(); }
  std::size_t particles() const { return rows.rows(); }
  std::int64_t begin(std::size_t i) const { return rows.begin(i); }
  std::int64_t end(std::size_t i) const { return rows.end(i); }
  /// Resizes the slot arrays to the arena (new slots are garbage).
  void fit_arena();
  /// Bytes held by the arrays (capacities).
  std::size_t bytes() const;
};

struct DualList {
  RowIndex rows;             ///< dual row of particle j: the bonds others own on j
  std::vector<BondId> bond;  ///< bond ids (sorted by id after a from-scratch build)

  std::int64_t begin(std::size_t j) const { return rows.begin(j); }
  std::int64_t end(std::size_t j) const { return rows.end(j); }
  /// Adds bond b to j's dual row (moving the row when it is full).
  void add(std::size_t j, BondId b);
  /// Removes bond b from j's dual row, keeping the order of the others.
  void remove(std::size_t j, BondId b);
  /// Bytes held by the arrays (capacities).
  std::size_t bytes() const;
};

/// Partial-volume factor β for a neighbour at distance `distance` with radius r_j (docs/theory.md
/// §7): r_j = Δx_j/2 for linear, the equal-measure radius for exact; unused by none.
double partial_volume_factor(PartialVolume rule, int dim, double distance, double horizon,
                             double r_j);

/// Fills p.radius with each particle's equal-measure radius (Section::equal_measure_radius).
void set_particle_radii(ParticleStore& p, const Section& section);

/// Builds every particle's bonds from the reference positions, horizons and spacings (and, for
/// exact partial volumes, the radii: every radius must be > 0).
BondList build_bonds(const ParticleStore& particles, PartialVolume rule,
                     const std::vector<geometry::Crack>& cracks);

/// The dual horizon of each particle: the bonds that others own on it.
DualList build_dual(const BondList& bonds);

/// The bonds of `bonds` after the particles are renumbered (order[k]: old index of new particle
/// k, new_index its inverse), packed without spare capacity, each row sorted by neighbour as a
/// from-scratch build leaves it; every bond keeps its length, weight, stiffness and state.
BondList renumbered_bonds(const BondList& bonds, const std::vector<std::int32_t>& order,
                          const std::vector<std::int32_t>& new_index);

/// The bonds particle i would get from scratch, found with `search_within(i, radius, out)`
/// (sorted candidate indices): neighbours, lengths and weights appended to the vectors.
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
  void keep_bonds(std::size_t i, std::vector<std::int32_t>& cand, std::vector<double>* length,
                  std::vector<double>* weight) const;

 private:
  const ParticleStore& p_;
  PartialVolume pv_;
  double reach_ = 0.0;
  const std::vector<geometry::Crack>& cracks_;
};

}  // namespace dhpd
