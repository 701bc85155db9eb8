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

bool segment_crosses_triangle(const Vec3& a, const Vec3& b, const Vec3& t0, const Vec3& t1,
                              const Vec3& t2) {
  const Vec3 normal = cross(t1 - t0, t2 - t0);
  const double da = dot(normal, a - t0), db = dot(normal, b - t0);
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return false;
  if (da == db) return false;  // segment parallel to (or inside) the plane: does not cut it
  const double t = da / (da - db);
  const Vec3 p = a + t * (b - a);
  const Vec3 c0 = cross(t1 - t0, p - t0), c1 = cross(t2 - t1, p - t1), c2 = cross(t0 - t2, p - t2);
  const double s0 = dot(c0, normal), s1 = dot(c1, normal), s2 = dot(c2, normal);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

}  // namespace

bool crosses(const Crack& crack, const Vec3& a, const Vec3& b, int dim) {
  const auto& p = crack.points;
  if (dim == 2) return segments_cross2d(a, b, p[0], p[1]);
  if (dim == 3)
    return segment_crosses_triangle(a, b, p[0], p[1], p[2]) ||
           segment_crosses_triangle(a, b, p[0], p[2], p[3]);
  return false;  // 1D: a crack is a point; not supported by the scene schema
}

bool is_planar(const Crack& crack, double rel_tol) {
  const auto& p = crack.points;
  if (p.size() != 4) return false;
  const Vec3 normal = cross(p[1] - p[0], p[2] - p[0]);
  const double scale = norm(p[1] - p[0]) * norm(p[2] - p[0]) * norm(p[3] - p[0]);
  if (scale == 0.0 || norm(normal) == 0.0) return false;
  return std::abs(dot(normal, p[3] - p[0])) <= rel_tol * scale;
}

}  // namespace dhpd::geometry
