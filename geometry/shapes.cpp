// Shape evaluation (containment, bounds) and the polygon checks the scene validator uses.
#include "geometry/shapes.hpp"

#include "geometry/predicates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dhpd::geometry {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double squared_distance(const Vec3& p, const Vec3& q, int dim) {
  double r2 = 0.0;
  for (int a = 0; a < dim; ++a) r2 += (p[a] - q[a]) * (p[a] - q[a]);
  return r2;
}

bool cylinder_contains(const Shape::Node& n, const Vec3& p) {
  const Vec3 axis = (1.0 / norm(n.b)) * n.b;
  const Vec3 d = p - n.a;
  const double t = dot(d, axis);
  if (t < 0.0 || t > n.height) return false;
  const Vec3 radial = d - t * axis;
  return dot(radial, radial) <= n.radius * n.radius;
}

Box cylinder_bounds(const Shape::Node& n) {
  const Vec3 axis = (1.0 / norm(n.b)) * n.b;
  const Vec3 top = n.a + n.height * axis;
  Box box;
  for (int a = 0; a < 3; ++a) {
    const double reach = n.radius * std::sqrt(std::max(0.0, 1.0 - axis[a] * axis[a]));
    box.min[a] = std::min(n.a[a], top[a]) - reach;
    box.max[a] = std::max(n.a[a], top[a]) + reach;
  }
  return box;
}

Box half_space_bounds(const Shape::Node& n, int dim) {
  Box box;
  int nonzero = 0, axis = 0;
  for (int a = 0; a < dim; ++a) {
    box.min[a] = -kInf, box.max[a] = kInf;
    if (n.b[a] != 0.0) ++nonzero, axis = a;
  }
  if (nonzero == 1) (n.b[axis] > 0 ? box.max[axis] : box.min[axis]) = n.a[axis];
  return box;
}

Box polygon_bounds(const std::vector<Vec3>& points) {
  Box box{{kInf, kInf, 0}, {-kInf, -kInf, 0}};
  for (const auto& p : points)
    for (int a = 0; a < 2; ++a)
      box.min[a] = std::min(box.min[a], p[a]), box.max[a] = std::max(box.max[a], p[a]);
  return box;
}

}  // namespace

bool Box::finite(int dim) const {
  for (int a = 0; a < dim; ++a)
    if (!std::isfinite(min[a]) || !std::isfinite(max[a])) return false;
  return true;
}

Shape::Shape(const Box& box) {
  Node n;
  n.kind = Kind::Box;
  n.a = box.min;
  n.b = box.max;
  nodes_.push_back(std::move(n));
}

Shape Shape::ball(const Vec3& center, double radius) {
  Node n;
  n.kind = Kind::Ball;
  n.a = center;
  n.radius = radius;
  return Shape(std::move(n));
}

Shape Shape::cylinder(const Vec3& base_center, const Vec3& axis, double radius, double height) {
  Node n;
  n.kind = Kind::Cylinder;
  n.a = base_center;
  n.b = axis;
  n.radius = radius;
  n.height = height;
  return Shape(std::move(n));
}

Shape Shape::polygon(std::vector<Vec3> points) {
  Node n;
  n.kind = Kind::Polygon;
  n.points = std::move(points);
  return Shape(std::move(n));
}

Shape Shape::half_space(const Vec3& point, const Vec3& normal) {
  Node n;
  n.kind = Kind::HalfSpace;
  n.a = point;
  n.b = normal;
  return Shape(std::move(n));
}

Shape Shape::combine(Kind kind, const std::vector<Shape>& operands) {
  Shape out;
  out.nodes_.clear();
  Node parent;
  parent.kind = kind;
  for (const auto& s : operands) {
    const int offset = static_cast<int>(out.nodes_.size());
    for (Node n : s.nodes_) {
      for (auto& c : n.children) c += offset;
      out.nodes_.push_back(std::move(n));
    }
    parent.children.push_back(offset + s.root());
  }
  out.nodes_.push_back(std::move(parent));
  return out;
}

Shape Shape::union_of(const std::vector<Shape>& operands) {
  return combine(Kind::Union, operands);
}

Shape Shape::difference(const std::vector<Shape>& operands) {
  return combine(Kind::Difference, operands);
}

bool Shape::contains(int index, const Vec3& p, int dim) const {
  const Node& n = node(index);
  switch (n.kind) {
    case Kind::Box:
      return Box{n.a, n.b}.contains(p, dim);
    case Kind::Ball:
      return squared_distance(p, n.a, dim) <= n.radius * n.radius;
    case Kind::Cylinder:
      return cylinder_contains(n, p);
    case Kind::Polygon:
      return polygon_contains(n.points, p);
    case Kind::HalfSpace: {
      double s = 0.0;
      for (int a = 0; a < dim; ++a) s += (p[a] - n.a[a]) * n.b[a];
      return s <= 0.0;
    }
    case Kind::Union:
      return std::any_of(n.children.begin(), n.children.end(),
                         [&](int c) { return contains(c, p, dim); });
    case Kind::Difference:
      if (n.children.empty() || !contains(n.children.front(), p, dim)) return false;
      return std::none_of(n.children.begin() + 1, n.children.end(),
                          [&](int c) { return contains(c, p, dim); });
  }
  return false;
}

Box Shape::bounds(int index, int dim) const {
  const Node& n = node(index);
  switch (n.kind) {
    case Kind::Box:
      return Box{n.a, n.b};
    case Kind::Ball: {
      Box box;
      for (int a = 0; a < dim; ++a) box.min[a] = n.a[a] - n.radius, box.max[a] = n.a[a] + n.radius;
      return box;
    }
    case Kind::Cylinder:
      return cylinder_bounds(n);
    case Kind::Polygon:
      return polygon_bounds(n.points);
    case Kind::HalfSpace:
      return half_space_bounds(n, dim);
    case Kind::Union: {
      Box box;
      for (int a = 0; a < dim; ++a) box.min[a] = kInf, box.max[a] = -kInf;
      for (const int c : n.children) {
        const Box b = bounds(c, dim);
        for (int a = 0; a < dim; ++a)
          box.min[a] = std::min(box.min[a], b.min[a]), box.max[a] = std::max(box.max[a], b.max[a]);
      }
      return box;
    }
    case Kind::Difference:
      return n.children.empty() ? Box{} : bounds(n.children.front(), dim);
  }
  return Box{};
}

bool polygon_contains(const std::vector<Vec3>& polygon, const Vec3& p) {
  return polygon_contains2d(polygon, p);
}

std::optional<std::pair<int, int>> polygon_self_intersection(const std::vector<Vec3>& polygon) {
  const int n = static_cast<int>(polygon.size());
  const auto at = [&](int k) -> const Vec3& { return polygon[static_cast<std::size_t>(k % n)]; };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (!adjacent) {
        if (segments_meet2d(at(i), at(i + 1), at(j), at(j + 1))) return std::make_pair(i, j);
        continue;
      }
      // Adjacent edges share one vertex; they overlap when they fold back along one line.
      const Vec3& shared = j == i + 1 ? at(j) : at(i);
      const Vec3& u = j == i + 1 ? at(i) : at(i + 1);
      const Vec3& w = j == i + 1 ? at(j + 1) : at(j);
      if (orient2d(u, shared, w) == 0.0 && dot(u - shared, w - shared) > 0.0)
        return std::make_pair(i, j);
    }
  return std::nullopt;
}

}  // namespace dhpd::geometry
