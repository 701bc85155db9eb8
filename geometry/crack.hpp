// Pre-cracks as geometry: a bond whose reference segment crosses a crack is never created
// (dhpd.md §7). 2D cracks are segments, 3D cracks planar polygons (3 or more corners in order).
#pragma once
#include <vector>

#include "geometry/vec.hpp"

namespace dhpd::geometry {

struct Crack {
  std::vector<Vec3> points;  ///< 2 points in 2D (a segment), >= 3 coplanar corners in 3D
};

/// Whether the closed segment a–b crosses the crack (touching counts as crossing).
bool crosses(const Crack& crack, const Vec3& a, const Vec3& b, int dim);

/// Whether the corners span a polygon of non-zero area lying in one plane (relative tolerance).
bool is_planar(const Crack& crack, double rel_tol = 1e-9);

}  // namespace dhpd::geometry
