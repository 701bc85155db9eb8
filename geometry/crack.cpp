// Segment–segment (2D) and segment–planar-quad (3D) crossing tests for pre-cracks (dhpd.md §7).
#include "geometry/crack.hpp"

#include <algorithm>
#include <cmath>

namespace dhpd::geometry {
namespace {

double orient2d(const Vec3& a, const Vec3& b, const Vec3& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

bool on_segment2d(const Vec3& a, const Vec3& b, const Vec3& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]);
}

bool segments_cross2d(const Vec3& p1, const Vec3& p2, const Vec3& q1, const Vec3& q2) {
  const double d1 = orient2d(q1, q2, p1), d2 = orient2d(q1, q2, p2);
  const double d3 = orient2d(p1, p2, q1), d4 = orient2d(p1, p2, q2);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  if (d1 == 0 && on_segment2d(q1, q2, p1)) return true;
  if (d2 == 0 && on_segment2d(q1, q2, p2)) return true;
  if (d3 == 0 && on_segment2d(p1, p2, q1)) return true;
  if (d4 == 0 && on_segment2d(p1, p2, q2)) return true;
  return false;
}

/// Newell's normal of a polygon (not normalised; zero for a degenerate one).
Vec3 polygon_normal(const std::vector<Vec3>& p) {
  Vec3 n{0, 0, 0};
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Vec3& a = p[k];
    const Vec3& b = p[(k + 1) % p.size()];
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return n;
}

/// Closed point-in-polygon test of q (in the polygon's plane), projected on the plane of the two
/// axes other than `drop` (the normal's dominant axis, so the projection keeps the shape).
bool inside_projected(const std::vector<Vec3>& p, const Vec3& q, int drop) {
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  bool inside = false;
  for (std::size_t k = 0, m = p.size() - 1; k < p.size(); m = k++) {
    const Vec3 a{p[m][u], p[m][v], 0}, b{p[k][u], p[k][v], 0}, x{q[u], q[v], 0};
    if (orient2d(a, b, x) == 0 && on_segment2d(a, b, x)) return true;  // on an edge
    if ((a[1] > x[1]) != (b[1] > x[1]) &&
        x[0] < (b[0] - a[0]) * (x[1] - a[1]) / (b[1] - a[1]) + a[0])
      inside = !inside;
  }
  return inside;
}

bool segment_crosses_polygon(const Vec3& a, const Vec3& b, const std::vector<Vec3>& poly) {
  const Vec3 normal = polygon_normal(poly);
  const double da = dot(normal, a - poly[0]), db = dot(normal, b - poly[0]);
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return false;
  if (da == db) return false;  // segment parallel to (or inside) the plane: does not cut it
  const double t = da / (da - db);
  const Vec3 q = a + t * (b - a);
  int drop = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[drop])) drop = k;
  return inside_projected(poly, q, drop);
}

}  // namespace

bool crosses(const Crack& crack, const Vec3& a, const Vec3& b, int dim) {
  const auto& p = crack.points;
  if (dim == 2) return segments_cross2d(a, b, p[0], p[1]);
  if (dim == 3) return segment_crosses_polygon(a, b, p);
  return false;  // 1D: a crack is a point; not supported by the scene schema
}

bool is_planar(const Crack& crack, double rel_tol) {
  const auto& p = crack.points;
  if (p.size() < 3) return false;
  const Vec3 normal = polygon_normal(p);
  const double area2 = norm(normal);  // twice the polygon's area
  double extent = 0.0;
  for (const auto& q : p) extent = std::max(extent, norm(q - p[0]));
  if (area2 <= 1e-12 * extent * extent) return false;  // collinear or zero-area corners
  for (const auto& q : p)
    if (std::abs(dot(normal, q - p[0])) > rel_tol * area2 * extent) return false;
  return true;
}

}  // namespace dhpd::geometry
