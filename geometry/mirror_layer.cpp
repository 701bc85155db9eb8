// Mirrored boundary layers (docs/theory.md §23).
#include "geometry/mirror_layer.hpp"

#include <algorithm>
#include <limits>

namespace dhpd::geometry {

double face_coordinate(const PointSet& points, int axis, int side) {
  double face =
      side > 0 ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double edge = points.position[i][axis] + 0.5 * side * points.spacing[i];
    face = side > 0 ? std::max(face, edge) : std::min(face, edge);
  }
  return face;
}

PointSet mirror_layer(const PointSet& points, int axis, int side, double width,
                      std::vector<std::int32_t>& mirrors) {
  const double face = face_coordinate(points, axis, side);
  PointSet out;
  mirrors.clear();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double depth = side * (face - points.position[i][axis]);
    if (!(depth < width)) continue;
    Vec3 x = points.position[i];
    x[axis] = 2.0 * face - x[axis];
    out.position.push_back(x);
    out.cell_measure.push_back(points.cell_measure[i]);
    out.spacing.push_back(points.spacing[i]);
    out.material.push_back(points.material[i]);
    out.part.push_back(points.part[i]);
    mirrors.push_back(static_cast<std::int32_t>(i));
  }
  return out;
}

}  // namespace dhpd::geometry
