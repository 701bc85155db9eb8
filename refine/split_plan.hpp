// The particle side of one refinement event (docs/theory.md §13.3; IJNME 2016 §5.3): which children
// each parent gets, where their state comes from, and writing them into the store through the field
// registry. The bond side is rebuild.* and no_healing.*; the event itself event.*.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "engine/discretization/section.hpp"
#include "geometry/crack.hpp"
#include "geometry/shapes.hpp"
#include "refine/spatial_grid.hpp"
#include "refine/state_mapping.hpp"

namespace dhpd::refine {

/// Offsets of the 2^dim children of a cell of spacing `dx`: ±dx/4 on each axis (docs/theory.md
/// §13.3).
std::vector<geometry::Vec3> child_offsets(int dim, double dx);

/// Where children may go: inside the body (when its shape is known). A child across a pre-crack
/// from its parent is created like any other (the uniform fine lattice has a particle there); its
/// state comes from its own side of the crack (`donors_across_cracks`).
struct ChildFilter {
  const std::optional<geometry::Shape>& body;
  int dim;
  bool allows(const geometry::Vec3& child) const;
};

/// The children of one event. Slots: a parent's first child takes the parent's slot (so particle
/// arrays never have holes and no index refers to a parent afterwards); the other children are
/// appended after the `old_size` particles, in Morton order of their positions.
struct SplitPlan {
  std::vector<std::int32_t> parents;           ///< slots of the parents that split
  std::vector<std::int32_t> child_count;       ///< per parent: children created (≤ 2^dim)
  std::vector<std::int32_t> child_parent;      ///< per child: index into `parents`
  std::vector<std::int32_t> child_slot;        ///< per child: its slot in the store
  std::vector<geometry::Vec3> child_position;  ///< per child: reference position
  std::size_t old_size = 0, new_size = 0;
  std::size_t dropped = 0;  ///< children not created (outside the body)
};

/// Validates `parents` (in range, no duplicates) and lays out their children. A child the filter
/// refuses is not created (its siblings share the parent's volume); a parent with no allowed child
/// is left unsplit.
SplitPlan plan_split(const ParticleStore& p, const std::vector<std::int32_t>& parents,
                     const ChildFilter& filter);

/// Per child of `plan`: −1 when no pre-crack separates it from its parent; otherwise the particle
/// that gives it its state, the nearest (lowest index among the nearest) within the parent's
/// horizon that it sees without crossing a crack, or −1 when there is none.
std::vector<std::int32_t> donors_across_cracks(const SplitPlan& plan, const ParticleStore& p,
                                               const std::vector<geometry::Crack>& cracks,
                                               const SpatialGrid& grid);

/// Resizes `p` to plan.new_size and writes every child through the field registry: Copy,
/// Shared (volume / children created), Reset (force density) or FromPattern (position,
/// spacing and horizon halved, radius recomputed, ids from `next_id` in child order, level + 1,
/// parent_id = the parent's id). Throws when a FromPattern field has no rule here.
void write_children(ParticleStore& p, const SplitPlan& plan, ParticleStore& parents,
                    const ChildState& state, const Section& section, std::int32_t next_id);

}  // namespace dhpd::refine
