// Reading shapes: `{shape: WORD, ...}` maps for body parts and regions, with the checks of each
// shape (schema in docs/scenes.md, "Shapes").
#include <fmt/format.h>

#include <algorithm>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

using geometry::Shape;
using geometry::Vec3;

const std::vector<std::string> kAllShapes{"box",      "disk",       "sphere",
                                          "cylinder", "polygon",    "half-space",
                                          "union",    "difference", "random-disks"};

/// The shape words a scene of dimension `dim` may use.
std::vector<std::string> shapes_for(int dim) {
  if (dim == 1) return {"box", "half-space", "union", "difference"};
  if (dim == 2)
    return {"box", "disk", "polygon", "half-space", "union", "difference", "random-disks"};
  return {"box", "sphere", "cylinder", "half-space", "union", "difference"};
}

std::vector<std::string> keys_of(const std::string& word) {
  if (word == "box") return {"shape", "min", "max"};
  if (word == "disk" || word == "sphere") return {"shape", "center", "radius"};
  if (word == "cylinder") return {"shape", "center", "axis", "radius", "height"};
  if (word == "polygon") return {"shape", "points"};
  if (word == "half-space") return {"shape", "point", "normal"};
  if (word == "random-disks")
    return {"shape", "min", "max", "count", "radius", "gap", "seed", "cover", "clear"};
  return {"shape", "of"};
}

int shape_dimension(const std::string& word) {
  if (word == "disk" || word == "polygon" || word == "random-disks") return 2;
  return word == "sphere" || word == "cylinder" ? 3 : 0;
}

std::string shape_word(const Cursor& c, int dim) {
  const Cursor word = MapView(c, {}).require("shape");
  if (word.node().IsScalar()) {
    const std::string text = word.node().Scalar();
    const int only = shape_dimension(text);
    if (only != 0 && only != dim)
      word.fail(fmt::format("shape '{}' exists only in {}D scenes; this scene has dimension {}",
                            text, only, dim),
                join(shapes_for(dim)));
  }
  return shapes_for(dim)[word.choice(shapes_for(dim))];
}

std::string point_text(const Vec3& p) {
  return fmt::format("[{}, {}]", p[0], p[1]);
}

std::vector<Vec3> polygon_points(const Cursor& c) {
  const auto items = c.list();
  if (items.size() < 3)
    c.fail(fmt::format("a polygon needs at least 3 points, got {}", items.size()), ">= 3 points");
  std::vector<Vec3> points;
  for (std::size_t k = 0; k < items.size(); ++k) {
    points.push_back(items[k].point(2));
    if (k > 0 && points[k] == points[k - 1])
      items[k].fail(fmt::format("point {} repeats point {} {}; give each corner once", k, k - 1,
                                point_text(points[k])));
  }
  if (points.back() == points.front())
    items.back().fail(
        fmt::format("the last point repeats the first {}; the polygon closes by "
                    "itself, give each corner once",
                    point_text(points.front())));
  if (const auto crossing = geometry::polygon_self_intersection(points)) {
    const auto edge = [&](int e) {
      const auto n = points.size();
      return fmt::format("edge {} {}-{}", e, point_text(points[static_cast<std::size_t>(e)]),
                         point_text(points[(static_cast<std::size_t>(e) + 1) % n]));
    };
    c.fail(fmt::format("the polygon intersects itself: {} and {} cross", edge(crossing->first),
                       edge(crossing->second)),
           "a simple polygon, corners in order around it");
  }
  return points;
}

Shape combination(const MapView& map, const std::string& word, int dim) {
  const Cursor of = map.require("of");
  const auto items = of.list();
  const std::size_t least = word == "union" ? 1 : 2;
  if (items.size() < least)
    of.fail(fmt::format("a {} needs at least {} operand{}, got {}", word, least,
                        least == 1 ? "" : "s", items.size()),
            fmt::format(">= {} shapes", least));
  std::vector<Shape> operands;
  for (const auto& item : items) operands.push_back(read_shape(item, dim));
  return word == "union" ? Shape::union_of(operands) : Shape::difference(operands);
}

Shape shape_of(const MapView& map, const std::string& word, int dim) {
  if (word == "box") {
    geometry::Box box;
    box.min = map.require("min").point(dim);
    const Cursor max = map.require("max");
    box.max = max.point(dim);
    check_box(max, box, dim);
    return box;
  }
  if (word == "disk" || word == "sphere")
    return Shape::ball(map.require("center").point(dim), positive_number(map.require("radius")));
  if (word == "cylinder") {
    const Vec3 center = map.require("center").point(dim);
    const Vec3 axis = nonzero_vector(map.require("axis"), dim);
    const double radius = positive_number(map.require("radius"));
    return Shape::cylinder(center, axis, radius, positive_number(map.require("height")));
  }
  if (word == "polygon") return Shape::polygon(polygon_points(map.require("points")));
  if (word == "half-space") {
    const Vec3 point = map.require("point").point(dim);
    return Shape::half_space(point, nonzero_vector(map.require("normal"), dim));
  }
  if (word == "random-disks") return read_random_disks(map);
  return combination(map, word, dim);
}

}  // namespace

Vec3 nonzero_vector(const Cursor& c, int dim) {
  const Vec3 v = c.point(dim);
  if (geometry::norm(v) == 0.0) c.fail(fmt::format("{} must not be the zero vector", c.key()));
  return v;
}

std::pair<Shape, MapView> shape_from(const Cursor& c, int dim,
                                     const std::vector<std::string>& extra) {
  const std::string word = shape_word(c, dim);
  auto allowed = keys_of(word);
  allowed.insert(allowed.end(), extra.begin(), extra.end());
  MapView map(c, allowed);
  Shape shape = shape_of(map, word, dim);
  return {std::move(shape), std::move(map)};
}

Shape read_shape(const Cursor& c, int dim) {
  return shape_from(c, dim, {}).first;
}

std::string shape_word(const Shape& shape, int index, int dim) {
  switch (shape.node(index).kind) {
    case Shape::Kind::Box:
      return "box";
    case Shape::Kind::Ball:
      return dim == 2 ? "disk" : "sphere";
    case Shape::Kind::Cylinder:
      return "cylinder";
    case Shape::Kind::Polygon:
      return "polygon";
    case Shape::Kind::HalfSpace:
      return "half-space";
    case Shape::Kind::Union:
      return "union";
    case Shape::Kind::Difference:
      return "difference";
  }
  return kAllShapes.front();
}

}  // namespace dhpd::scene::detail
