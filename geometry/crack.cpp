// Segment–segment (2D) and segment–planar-polygon (3D) crossing tests for pre-cracks
// (docs/theory.md §8).
#include "geometry/crack.hpp"

#include "geometry/predicates.hpp"

#include <algorithm>
#include <cmath>

namespace dhpd::geometry {
namespace {

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

bool segment_crosses_polygon(const Vec3& a, const Vec3& b, const std::vector<Vec3>& poly) {
  const Vec3 normal = polygon_normal(poly);
  const double da = dot(normal, a - poly[0]), db = dot(normal, b - poly[0]);
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return false;
  if (da == db) return false;  // segment parallel to (or inside) the plane: does not cut it
  const double t = da / (da - db);
  const Vec3 q = a + t * (b - a);
  // Project on the plane of the two axes other than the normal's dominant one (keeps the shape).
  int drop = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[drop])) drop = k;
  return polygon_contains2d(poly, q, drop == 0 ? 1 : 0, drop == 2 ? 1 : 2);
}

}  // namespace

bool crosses(const Crack& crack, const Vec3& a, const Vec3& b, int dim) {
  const auto& p = crack.points;
  if (dim == 2) return segments_meet2d(a, b, p[0], p[1]);
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

std::vector<CrackFront> crack_fronts(const Crack& crack, int dim, double step,
                                     const std::function<bool(const Vec3&)>& inside) {
  std::vector<CrackFront> out;
  const auto& p = crack.points;
  if (dim == 2) {
    for (int e = 0; e < 2; ++e) {
      const Vec3 end = p[static_cast<std::size_t>(e)], from = p[static_cast<std::size_t>(1 - e)];
      const Vec3 out_dir = (1.0 / norm(end - from)) * (end - from);
      if (inside(end + step * out_dir)) out.push_back({end, end});
    }
    return out;
  }
  Vec3 centroid{0, 0, 0}, normal{0, 0, 0};
  for (const auto& q : p) centroid = centroid + (1.0 / static_cast<double>(p.size())) * q;
  for (std::size_t k = 0; k < p.size(); ++k)
    normal = normal + cross(p[k] - centroid, p[(k + 1) % p.size()] - centroid);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Vec3 a = p[k], b = p[(k + 1) % p.size()], mid = 0.5 * (a + b);
    Vec3 out_dir = cross(b - a, normal);
    if (dot(out_dir, mid - centroid) < 0) out_dir = -1.0 * out_dir;
    out_dir = (1.0 / norm(out_dir)) * out_dir;
    if (inside(mid + step * out_dir)) out.push_back({a, b});
  }
  return out;
}

double distance_to(const CrackFront& f, const Vec3& x) {
  const Vec3 ab = f.b - f.a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(dot(x - f.a, ab) / len2, 0.0, 1.0) : 0.0;
  return norm(x - (f.a + t * ab));
}

}  // namespace dhpd::geometry
