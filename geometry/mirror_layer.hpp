// The points of a fictitious boundary layer (docs/theory.md §23): the body's points within a
// width of one of its bounding faces, mirrored across it (the same lattice, continued outside).
#pragma once
#include <cstdint>
#include <vector>

#include "geometry/lattice.hpp"

namespace dhpd::geometry {

/// The coordinate along `axis` of the points' bounding face on `side` (+1: largest, −1: smallest),
/// cells included (x ± spacing/2).
double face_coordinate(const PointSet& points, int axis, int side);

/// The points within `width` of that face (their centres), mirrored across it, with their cell
/// measure, spacing, material and part; `mirrors[k]` is the index of the point new point k mirrors.
PointSet mirror_layer(const PointSet& points, int axis, int side, double width,
                      std::vector<std::int32_t>& mirrors);

}  // namespace dhpd::geometry
