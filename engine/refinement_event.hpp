// The mechanics of one refinement event (dhpd.md §8; IJNME 2016 §5.3): splitting parents through
// the field registry, and the no-healing rule for the bonds of the new generation. Which particles
// to split (triggers, buffer, grading) is decided in refine/.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/bonds.hpp"
#include "engine/particles.hpp"
#include "engine/settings.hpp"

namespace dhpd {

/// The particles of the next generation and where each came from.
struct SplitResult {
  ParticleStore particles;
  /// Index in the previous generation of each new particle: itself when kept, its parent when a
  /// child. Kept particles come first in their old order, then the children parent by parent.
  std::vector<std::int32_t> previous;
  std::size_t kept = 0;  ///< particles of the previous generation that were not split
  std::size_t children = 0;
};

/// Offsets of the 2^dim children of a cell of spacing `dx`: ±dx/4 on each axis (dhpd.md §8).
std::vector<geometry::Vec3> child_offsets(int dim, double dx);

/// Splits every parent (indices into `p`, any order, no duplicates) into 2^dim children and drops
/// the parents. Every registered field follows its SplitRule: Copy, DivideByChildren (volume),
/// Reset (force density) or FromPattern (position ±Δx/4, spacing and horizon halved, radius
/// recomputed, new ids from `next_id`, level + 1, parent_id = the parent's id). The children of a
/// lattice cell lie inside that cell, so inside the body whenever the parent's cell is.
SplitResult split_particles(const ParticleStore& p, const std::vector<std::int32_t>& parents,
                            const Section& section, std::int32_t next_id);

/// How children get their displacement (velocity is always copied, so momentum and kinetic
/// energy are conserved exactly either way).
enum class StateMapping {
  Copy,    ///< u_child = u_parent (a piecewise-constant field: bonds between children of two
           ///< parents start with twice the local strain)
  Linear,  ///< u_child = u_parent + G·(X_child − X_parent), G the least-squares displacement
           ///< gradient over the parent's intact own bonds (copy when they do not span the space)
};

/// Applies `mapping` to the children of `split` (displacement and current position only).
void map_displacement(SplitResult& split, StateMapping mapping, const ParticleStore& old_p,
                      const BondList& old_bonds);

/// The no-healing rule: sets `bonds.intact` of every bond of the new generation from the broken
/// bonds of the previous one. A new bond i→j starts broken when
///  (a) the endpoints come from two different previous particles P ≠ Q that were bonded (P→Q or
///      Q→P) and one of those bonds was broken; or
///  (b) P and Q had no bond and the reference segment i–j properly crosses old bond segments:
///      for a coarse particle reaching a child its horizon did not reach before, when any crossing
///      old bond was broken; for siblings of one parent, when more than half of the crossing old
///      bonds (not counting the parent's own) were broken. A single long broken bond passing over
///      a cell says little about where along it the crack lies; a cell inside a fragmented zone is
///      crossed mostly by broken bonds. (Breaking siblings on any crossing broken bond gave
///      children far from the crack a damage of about 0.05 at birth in cracked-plate-adaptive.)
/// When P and Q were bonded and intact the new bond is intact: a crossing test there would break
/// every bond that a long broken bond passes over on the uncracked side. Crossing is a proper
/// intersection in the plane; in 1D and 3D rule (b) finds nothing and only (a) applies.
/// A bond between two kept particles (the first `kept` of the new generation) keeps the state of
/// the same bond before. Returns the number of new bonds that start broken.
std::int64_t apply_no_healing(BondList& bonds, const ParticleStore& p,
                              const std::vector<std::int32_t>& previous, std::size_t kept,
                              const BondList& old_bonds, const ParticleStore& old_p);

/// Whether the planar segments a–b and c–d cross at a single point interior to both.
bool segments_cross_properly(const geometry::Vec3& a, const geometry::Vec3& b,
                             const geometry::Vec3& c, const geometry::Vec3& d);

}  // namespace dhpd
