// Randomly placed, non-overlapping disks in a box, reproducible from a seed: the inclusion layouts
// of CMAME 2017 §5.2 ("many randomly distributed inclusions"). Random sequential addition: each
// disk draws a radius and then centres until one keeps the gap to every disk placed before.
//
// Reproducible on every platform: the generator is std::mt19937_64 (its output is fixed by the
// C++ standard) and the draws are made from its raw bits here, not by std:: distributions (whose
// results the standard leaves to the library).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/shapes.hpp"
#include "geometry/vec.hpp"

namespace dhpd::geometry {

struct RandomDisksSpec {
  Box box;  ///< every disk lies inside it (2D)
  int count = 1;
  double radius_min = 0.0, radius_max = 0.0;  ///< radii are uniform in [min, max]
  double gap = 0.0;                           ///< least distance between two rims
  std::uint64_t seed = 0;
  std::vector<Vec3> cover;  ///< each point lies inside one disk (those disks come first)
  std::vector<Vec3> clear;  ///< each point stays at least `gap` outside every disk
};

/// Centre draws per disk before the layout is given up.
inline constexpr int kRandomDiskDraws = 1000;

struct RandomDisks {
  std::vector<Vec3> centers;
  std::vector<double> radii;
  /// Set when disk `failed` (0-based) found no place in kRandomDiskDraws draws; the disks before
  /// it are kept.
  std::optional<int> failed;
  /// The share of the box the placed disks cover.
  double covered_fraction(const Box& box) const;
  /// The union of the disks (for a scene region).
  Shape shape() const;
};

/// Places spec.count disks; the caller checks the spec (radii > 0, min <= max, box wider than the
/// largest disk, gap >= 0).
RandomDisks place_random_disks(const RandomDisksSpec& spec);

}  // namespace dhpd::geometry
