// Shapes used for body parts and regions: boxes, disks and spheres, cylinders, polygons,
// half-spaces, and their unions and differences. Shapes are evaluated only at set-up, never in the
// time loop.
//
// Boundary convention: every primitive is a closed set (a point on its boundary is inside). A
// union holds the points inside any operand; a difference A − B − ... holds the points inside A
// and inside none of the others, so a point on the rim of a hole is not in the difference.
#pragma once
#include <optional>
#include <utility>
#include <vector>

#include "geometry/vec.hpp"

namespace dhpd::geometry {

/// Axis-aligned box [min, max] in `dim` dimensions; unused axes are ignored.
struct Box {
  Vec3 min{0, 0, 0};
  Vec3 max{0, 0, 0};

  bool contains(const Vec3& p, int dim) const {
    for (int a = 0; a < dim; ++a)
      if (p[a] < min[a] || p[a] > max[a]) return false;
    return true;
  }
  /// True when the two boxes share any point in the first `dim` axes.
  bool intersects(const Box& o, int dim) const {
    for (int a = 0; a < dim; ++a)
      if (o.max[a] < min[a] || o.min[a] > max[a]) return false;
    return true;
  }
  double measure(int dim) const {
    double m = 1.0;
    for (int a = 0; a < dim; ++a) m *= max[a] - min[a];
    return m;
  }
  /// True when every bound of the first `dim` axes is finite.
  bool finite(int dim) const;
  bool operator==(const Box&) const = default;
};

/// A shape as a small tree of nodes; children refer to earlier nodes by index and the root is the
/// last node. A plain value: copyable, comparable, no virtual calls.
class Shape {
 public:
  enum class Kind { Box, Ball, Cylinder, Polygon, HalfSpace, Union, Difference };
  struct Node {
    Kind kind = Kind::Box;
    Vec3 a{0, 0, 0};  ///< box min, ball/cylinder centre (of the base), half-space point
    Vec3 b{0, 0, 0};  ///< box max, cylinder axis, half-space normal
    double radius = 0.0;
    double height = 0.0;
    std::vector<Vec3> points;   ///< polygon vertices in order (2D)
    std::vector<int> children;  ///< union/difference operands
    bool operator==(const Node&) const = default;
  };

  Shape() : Shape(Box{}) {}
  Shape(const Box& box);  // NOLINT: a box is a shape
  static Shape ball(const Vec3& center, double radius);
  static Shape cylinder(const Vec3& base_center, const Vec3& axis, double radius, double height);
  static Shape polygon(std::vector<Vec3> points);
  static Shape half_space(const Vec3& point, const Vec3& normal);
  static Shape union_of(const std::vector<Shape>& operands);
  /// The first operand minus all the others.
  static Shape difference(const std::vector<Shape>& operands);

  bool contains(const Vec3& p, int dim) const { return contains(root(), p, dim); }
  /// Axis-aligned bounds; infinite on the axes a half-space leaves open.
  Box bounds(int dim) const { return bounds(root(), dim); }

  const std::vector<Node>& nodes() const { return nodes_; }
  int root() const { return static_cast<int>(nodes_.size()) - 1; }
  const Node& node(int index) const { return nodes_[static_cast<std::size_t>(index)]; }
  bool operator==(const Shape&) const = default;

 private:
  explicit Shape(Node node) : nodes_{std::move(node)} {}
  static Shape combine(Kind kind, const std::vector<Shape>& operands);
  bool contains(int index, const Vec3& p, int dim) const;
  Box bounds(int index, int dim) const;

  std::vector<Node> nodes_;
};

/// Point-in-polygon for a simple polygon (crossing rule); points on an edge are inside.
bool polygon_contains(const std::vector<Vec3>& polygon, const Vec3& p);

/// For a polygon whose consecutive points differ: the first pair of edges (i, j), i < j, that
/// cross, touch or overlap other than at the vertex adjacent edges share; edge k runs from point k
/// to point k + 1 (the last edge back to point 0).
std::optional<std::pair<int, int>> polygon_self_intersection(const std::vector<Vec3>& polygon);

}  // namespace dhpd::geometry
