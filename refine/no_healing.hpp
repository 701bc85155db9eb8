// The no-healing rule of refinement (docs/theory.md §13.5; IJNME 2016 §5.3: a crack must not close
// when its surroundings are refined): which bonds of a new generation start broken, decided from
// the broken bonds of the previous generation. One rule, used by the incremental event and by the
// from-scratch reference the tests compare it with.
#pragma once
#include <array>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"

namespace dhpd::refine {

/// The previous generation as the rule sees it: its bond rows (indices = previous indices) and
/// its reference positions. During an incremental event the store already holds the children in
/// the parents' slots, so the parents' old positions come from `parents` (their snapshot), looked
/// up by `parent_slot[x]` (−1 for particles that were not split).
struct OldGeneration {
  const BondRows& bonds;
  const ParticleStore& particles;
  const ParticleStore* parents = nullptr;
  const std::vector<std::int32_t>* parent_slot = nullptr;

  geometry::Vec3 position(std::int32_t x) const;
};

/// Bonds of the previous generation as reference segments, binned by midpoint: the rows of the
/// given owners (all particles for a from-scratch check, the neighbourhood of the parents for an
/// event).
class OldSegments {
 public:
  OldSegments(const OldGeneration& old, std::vector<std::int32_t> owners);
  bool any_broken() const { return !broken_.empty(); }

  struct Crossings {
    std::size_t all = 0, broken = 0;
  };
  /// Old bonds that cross a–b (a proper crossing in the plane; in 3D passing through the tube of
  /// radius `tube` around a–b, interior to both), skipping those that touch particle `skip`.
  /// `all` is counted only when `count_all` and some broken bond crosses (it is the expensive
  /// part: a point of a 3D body lies near thousands of bonds), and only up to twice `broken`
  /// (whether the broken ones are more than half); without `count_all`, `broken` is 0 or 1
  /// (whether any crosses).
  Crossings crossing(const geometry::Vec3& a, const geometry::Vec3& b, std::int32_t skip,
                     double tube, bool count_all) const;

 private:
  struct Segment {
    std::int32_t owner, neighbor;  ///< its ends (their previous reference positions: old_)
  };
  /// Segments sorted by the cell of their midpoint, over the box of cells that holds them (a
  /// dense grid: a query reads its cells by index, not by hashing).
  struct Bins {
    double cell = 1.0;  ///< cell width
    std::int64_t lo[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    std::vector<std::int64_t> first;  ///< per cell, its first segment; the count at the end
    std::vector<Segment> segments;
    /// Per segment its box in floats rounded outwards (lows, then highs): a query reads these 24
    /// bytes and looks up the ends of the few whose box meets its own.
    std::vector<std::array<float, 6>> boxes;
    bool empty() const { return segments.empty(); }
  };
  Bins binned(const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs) const;
  /// Segments of `bins` that cross a–b, counted up to `enough` (then it stops).
  std::size_t count(const Bins& bins, const geometry::Vec3& a, const geometry::Vec3& b,
                    std::int32_t skip, double tube, std::size_t enough) const;
  static constexpr std::size_t kEvery = static_cast<std::size_t>(-1);

  const OldGeneration& old_;
  std::vector<std::int32_t> owners_;
  Bins broken_;
  mutable Bins all_;  ///< built on first use (by one thread; the others wait for it)
  mutable std::once_flag all_built_;
  double max_length_ = 0.0;
  int dim_ = 2;
};

/// A new bond i→j whose ends come from previous particles P = previous(i), Q = previous(j) starts
/// broken when
///  (a) P ≠ Q were bonded (P→Q or Q→P; only P→Q when both i and j are unsplit particles, whose own
///      bond keeps its state) and one of those bonds was broken; or
///  (b) P and Q had no bond and old bonds cross the reference segment i–j: for a coarse particle
///      reaching a child its horizon did not reach before, when any crossing old bond was broken;
///      for siblings of one parent, when more than half of the crossing old bonds (not counting the
///      parent's own) were broken. A single long broken bond passing over a cell says little about
///      where along it the crack lies; a cell inside a fragmented zone is crossed mostly by broken
///      bonds. (Breaking siblings on any crossing broken bond gave children far from the crack a
///      damage of about 0.05 at birth in branching_plate_adaptive.)
/// When P and Q were bonded and intact the new bond is intact: a crossing test there would break
/// every bond that a long broken bond passes over on the uncracked side. In 1D only (a) applies.
/// `tube` is the 3D crossing radius (half the finer end's spacing).
bool starts_broken(const OldGeneration& old, const OldSegments& segments, const geometry::Vec3& xi,
                   const geometry::Vec3& xj, std::int32_t P, std::int32_t Q, bool both_unsplit,
                   double tube);

/// The rule applied from scratch to every bond of a new generation: `previous[i]` is the previous
/// index of new particle i (its parent for a child), `born[i]` is 1 for children. Sets the intact
/// bits of `bonds` (own and dual side) and returns the number of bonds that start broken.
std::int64_t apply_no_healing(BondRows& bonds, const ParticleStore& p,
                              const std::vector<std::int32_t>& previous,
                              const std::vector<std::uint8_t>& born, const BondRows& old_bonds,
                              const ParticleStore& old_p);

/// The second birth rule of an event's bonds: a new bond that no-healing leaves intact starts
/// broken when the mapped state already stretches it to its owner's critical stretch or beyond,
/// s = |y_j − y_i| / |ξ| − 1 ≥ s0_i, on the squared ratio as the force kernel tests it (what the
/// next fracture pass would do; decided here so that the event log counts it as
/// `started_overstretched`). Owners flagged no_fail never start broken. The state mapping keeps
/// this at zero where the parents' field is linear (docs/scenes.md).
bool starts_overstretched(const ParticleStore& p, std::size_t owner, std::size_t neighbor,
                          double inverse_length, double owner_critical_stretch);

/// Whether the planar segments a–b and c–d cross at a single point interior to both.
bool segments_cross_properly(const geometry::Vec3& a, const geometry::Vec3& b,
                             const geometry::Vec3& c, const geometry::Vec3& d);

/// Whether segment c–d passes within `tube` of segment a–b at points interior to both (3D).
bool segment_passes_through_tube(const geometry::Vec3& a, const geometry::Vec3& b,
                                 const geometry::Vec3& c, const geometry::Vec3& d, double tube);

}  // namespace dhpd::refine
