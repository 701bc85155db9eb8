// Checks on a point set that would make a run unstable: coincident points (a zero-length bond
// has no direction), non-positive or non-finite cell measures and spacings (zero mass).
#pragma once
#include <cstddef>
#include <optional>
#include <utility>

#include "geometry/lattice.hpp"

namespace dhpd::geometry {

/// The first point (lowest index) whose cell measure or spacing is not a positive finite number.
std::optional<std::size_t> first_degenerate_point(const PointSet& points);

/// A pair (i < j) of points closer than `relative` times the smaller of their spacings; the pair
/// with the smallest j, then the smallest i. Spacings must be positive. O(n log n).
std::optional<std::pair<std::size_t, std::size_t>> first_coincident_pair(const PointSet& points,
                                                                         int dim,
                                                                         double relative = 1e-6);

}  // namespace dhpd::geometry
