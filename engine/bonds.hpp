// Bonds in flat CSR per owner plus the dual-horizon lists (dhpd.md §1, §6, §7).
// Bond b (owner i, neighbour j) is created for every j with β_ij > 0 whose reference segment
// crosses no crack: j in H_i for none/linear, and up to δ_i + r_j for exact (a particle partly
// inside the horizon). The dual list of j holds the ids of the bonds others own on j.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/particles.hpp"
#include "engine/settings.hpp"
#include "geometry/crack.hpp"

namespace dhpd {

using BondId = std::int32_t;

struct BondList {
  std::vector<std::int64_t> offset;  ///< row of owner i is [offset[i], offset[i+1])
  std::vector<std::int32_t> owner;   ///< owner of each bond (redundant with offset; O(1) lookup)
  std::vector<std::int32_t> neighbor;
  std::vector<double> length;        ///< |ξ| in the reference configuration
  std::vector<double> weight;        ///< partial-volume factor β_ij
  std::vector<std::uint8_t> intact;  ///< μ_ij: 1 until the bond breaks, never healed

  std::size_t size() const { return neighbor.size(); }
  std::size_t particles() const { return offset.empty() ? 0 : offset.size() - 1; }
};

struct DualList {
  std::vector<std::int64_t> offset;  ///< dual row of particle j
  std::vector<BondId> bond;          ///< ids of bonds i→j owned by others, sorted by id
};

/// Partial-volume factor β for a neighbour at distance `distance` with radius r_j (dhpd.md §6):
/// r_j = Δx_j/2 for linear, the equal-measure radius for exact; unused by none.
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

}  // namespace dhpd
