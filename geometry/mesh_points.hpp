// Particles from a triangle mesh (CMAME 2017 §6): every mesh node becomes a particle that stands
// for one third of the area of each triangle it belongs to. The mesh itself is a CGAL constrained
// Delaunay triangulation refined by Delaunay_mesher_2; CGAL stays inside mesh_points.cpp.
#pragma once
#include <array>
#include <vector>

#include "geometry/lattice.hpp"
#include "geometry/point_size.hpp"
#include "geometry/shapes.hpp"

namespace dhpd::geometry {

/// Target edge length of the mesh: h(x) = size + rate · |x − from| (rate = 0: uniform).
/// `size` bounds the longest edge of every triangle near `from`; the bound grows linearly with
/// the distance from `from` at slope `rate` (dimensionless, >= 0).
struct MeshSize {
  double size = 0.0;
  double rate = 0.0;
  Vec3 from{0, 0, 0};

  double at(const Vec3& x) const { return size + rate * norm(x - from); }
};

/// Smallest sine² of a triangle angle the mesher accepts (0.125: angles above about 20.7°, the
/// bound for which Delaunay refinement is guaranteed to terminate).
inline constexpr double kMeshShapeBound = 0.125;

/// A 2D polygon (vertices in order, either orientation, not closed: the last vertex joins the
/// first) meshed with triangles no longer than `size` allows. Each node gets the cell measure
/// Σ area/3 of its triangles, spacing point_size(cell measure, 2, `rule`) (by default the
/// equivalent diameter 2·sqrt(area/π), CMAME 2017 §6), `material` and part index `part`. Throws
/// std::invalid_argument for fewer than 3 vertices or a non-positive size.
PointSet mesh_polygon(const std::vector<std::array<double, 2>>& boundary, const MeshSize& size,
                      int material, int part = 0, PointSize rule = PointSize::EquivalentDiameter);

/// An axis-aligned box meshed as above (dim 2) or with tetrahedra (dim 3, mesh_box_3d); dim 1
/// throws std::invalid_argument.
PointSet mesh_box(const Box& box, int dim, const MeshSize& size, int material, int part = 0,
                  PointSize rule = PointSize::EquivalentDiameter);

/// A box meshed with CGAL Mesh_3, its edges and corners protected so the tetrahedra fill it
/// exactly; `size` bounds edges, boundary facets and cell radii. Each node gets a quarter of the
/// volume of each of its tetrahedra and spacing point_size(volume, 3, `rule`) (by default the
/// equivalent diameter cbrt(6·volume/π)).
PointSet mesh_box_3d(const Box& box, const MeshSize& size, int material, int part = 0,
                     PointSize rule = PointSize::EquivalentDiameter);

}  // namespace dhpd::geometry
