// Plane predicates shared by shapes, pre-cracks and the no-healing rule (plain doubles; the
// robust overlap classification lives in intersection.cpp). Axes u, v pick the plane of a
// projection (0, 1 is the x–y plane).
#pragma once
#include <algorithm>
#include <vector>

#include "geometry/vec.hpp"

namespace dhpd::geometry {

/// (b − a) × (c − a) in the (u, v) plane: > 0 when a, b, c turn left.
inline double orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int u = 0, int v = 1) {
  return (b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]);
}

/// p lies on the closed segment [a, b].
inline bool on_segment2d(const Vec3& a, const Vec3& b, const Vec3& p, int u = 0, int v = 1) {
  return orient2d(a, b, p, u, v) == 0.0 && std::min(a[u], b[u]) <= p[u] &&
         p[u] <= std::max(a[u], b[u]) && std::min(a[v], b[v]) <= p[v] &&
         p[v] <= std::max(a[v], b[v]);
}

/// The closed segments [a, b] and [c, d] share at least one point (touching counts).
inline bool segments_meet2d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double o1 = orient2d(a, b, c), o2 = orient2d(a, b, d);
  const double o3 = orient2d(c, d, a), o4 = orient2d(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  return on_segment2d(a, b, c) || on_segment2d(a, b, d) || on_segment2d(c, d, a) ||
         on_segment2d(c, d, b);
}

/// p lies in the closed polygon (vertices in order, simple) projected on the (u, v) plane.
inline bool polygon_contains2d(const std::vector<Vec3>& polygon, const Vec3& p, int u = 0,
                               int v = 1) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Vec3& a = polygon[j];
    const Vec3& b = polygon[i];
    if (on_segment2d(a, b, p, u, v)) return true;
    // Crossing rule: count edges that straddle the line v = p_v to the right of p.
    if ((a[v] > p[v]) != (b[v] > p[v]) &&
        p[u] < a[u] + (p[v] - a[v]) * (b[u] - a[u]) / (b[v] - a[v]))
      inside = !inside;
  }
  return inside;
}

}  // namespace dhpd::geometry
