// Pre-cracks as geometry: a bond whose reference segment crosses a crack is never created
// (docs/theory.md §8). 2D cracks are segments, 3D cracks planar polygons (3 or more corners in
// order).
#pragma once
#include <functional>
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

/// A piece of a pre-crack's front: an end point in 2D (a == b), an edge in 3D.
struct CrackFront {
  Vec3 a, b;
};

/// The fronts of a crack: the end points (2D) or edges (3D) beyond which, in the crack's plane,
/// the body goes on: `inside(x)` at `step` past the front. A crack from a free edge has its mouth
/// outside and a single front.
std::vector<CrackFront> crack_fronts(const Crack& crack, int dim, double step,
                                     const std::function<bool(const Vec3&)>& inside);

/// Distance from x to a front (a point or a segment).
double distance_to(const CrackFront& front, const Vec3& x);

}  // namespace dhpd::geometry
