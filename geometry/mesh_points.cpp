// Mesh → particles (CMAME 2017 §6): CGAL constrained Delaunay triangulation of the boundary,
// Delaunay refinement with a size field and a shape bound, then each node takes a third of the
// area of each incident triangle and Δx its equivalent diameter. CGAL is included here only
// (never in a header).
#include "geometry/mesh_points.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace dhpd::geometry {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Delaunay_mesh_vertex_base_2<Kernel>;
using FaceBase = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

Vec3 to_vec(const Cdt::Point& p) {
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), 0.0};
}

/// Delaunay refinement criteria with a position-dependent edge-length bound: a triangle whose
/// longest edge exceeds h(centroid) must be split; otherwise it is bad when its smallest angle's
/// sine² is below the shape bound. Same interface as CGAL's Delaunay_mesh_size_criteria_2.
class GradedCriteria {
 public:
  using Face_handle = Cdt::Face_handle;

  /// first: sine² of the smallest angle; second: (longest edge / local bound)².
  struct Quality : std::pair<double, double> {
    Quality() = default;
    Quality(double sine, double size) : std::pair<double, double>(sine, size) {}
    double sine() const { return first; }
    double size() const { return second; }
    /// q1 < q2: q1 is refined first (too-long triangles by length, then by shape).
    bool operator<(const Quality& q) const {
      if (size() > 1) return q.size() > 1 ? size() > q.size() : true;
      if (q.size() > 1) return false;
      return sine() < q.sine();
    }
  };

  class Is_bad {
   public:
    Is_bad(const MeshSize& size, double shape) : size_(size), shape_(shape) {}

    CGAL::Mesh_2::Face_badness operator()(const Quality& q) const {
      if (q.size() > 1) return CGAL::Mesh_2::IMPERATIVELY_BAD;
      return q.sine() < shape_ ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
    }

    CGAL::Mesh_2::Face_badness operator()(const Face_handle& fh, Quality& q) const {
      const Vec3 a = to_vec(fh->vertex(0)->point()), b = to_vec(fh->vertex(1)->point()),
                 c = to_vec(fh->vertex(2)->point());
      double edges[3] = {dot(b - c, b - c), dot(c - a, c - a), dot(a - b, a - b)};
      std::sort(edges, edges + 3);
      const Vec3 centroid = (1.0 / 3.0) * (a + b + c);
      const double bound = size_.at(centroid);
      q.second = edges[2] / (bound * bound);
      if (q.size() > 1) {
        q.first = 1;
        return CGAL::Mesh_2::IMPERATIVELY_BAD;
      }
      const double twice_area = cross(b - a, c - a)[2];
      q.first = twice_area * twice_area / (edges[2] * edges[1]);
      return q.sine() < shape_ ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
    }

   private:
    MeshSize size_;
    double shape_;
  };

  explicit GradedCriteria(const MeshSize& size) : size_(size) {}
  Is_bad is_bad_object() const { return Is_bad(size_, kMeshShapeBound); }

 private:
  MeshSize size_;
};

/// One third of every in-domain triangle's area to each of its nodes, in vertex order.
PointSet lump_areas(const Cdt& cdt, int material, int part, PointSize rule) {
  std::map<Cdt::Vertex_handle, std::size_t> index;
  PointSet out;
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
    index.emplace(v, out.size());
    out.position.push_back(to_vec(v->point()));
    out.cell_measure.push_back(0.0);
  }
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    const Vec3 a = to_vec(f->vertex(0)->point()), b = to_vec(f->vertex(1)->point()),
               c = to_vec(f->vertex(2)->point());
    const double share = std::abs(cross(b - a, c - a)[2]) / 6.0;
    for (int k = 0; k < 3; ++k) out.cell_measure[index.at(f->vertex(k))] += share;
  }
  // Nodes that touch no in-domain triangle (outside a non-convex boundary) are dropped.
  PointSet kept;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!(out.cell_measure[i] > 0.0)) continue;
    kept.position.push_back(out.position[i]);
    kept.cell_measure.push_back(out.cell_measure[i]);
    kept.spacing.push_back(point_size(out.cell_measure[i], 2, rule));
    kept.material.push_back(material);
    kept.part.push_back(part);
  }
  return kept;
}

}  // namespace

PointSet mesh_polygon(const std::vector<std::array<double, 2>>& boundary, const MeshSize& size,
                      int material, int part, PointSize rule) {
  if (boundary.size() < 3) throw std::invalid_argument("a mesh boundary needs at least 3 points");
  if (!(size.size > 0.0) || !(size.rate >= 0.0))
    throw std::invalid_argument("the mesh size must be > 0 and its grading rate >= 0");
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> corners;
  for (const auto& p : boundary) corners.push_back(cdt.insert(Cdt::Point(p[0], p[1])));
  for (std::size_t k = 0; k < corners.size(); ++k)
    cdt.insert_constraint(corners[k], corners[(k + 1) % corners.size()]);
  CGAL::refine_Delaunay_mesh_2(cdt, GradedCriteria(size));
  return lump_areas(cdt, material, part, rule);
}

PointSet mesh_box(const Box& box, int dim, const MeshSize& size, int material, int part,
                  PointSize rule) {
  if (dim == 3) return mesh_box_3d(box, size, material, part, rule);
  if (dim != 2) throw std::invalid_argument("meshing is available for 2D and 3D parts only");
  const std::vector<std::array<double, 2>> corners{{box.min[0], box.min[1]},
                                                   {box.max[0], box.min[1]},
                                                   {box.max[0], box.max[1]},
                                                   {box.min[0], box.max[1]}};
  return mesh_polygon(corners, size, material, part, rule);
}

}  // namespace dhpd::geometry
