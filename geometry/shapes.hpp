// Shapes used for bodies and regions. Only axis-aligned boxes for now; the geometry issue adds
// more.
#pragma once
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
};

}  // namespace dhpd::geometry
