// 3D mesh → particles: CGAL Mesh_3 on a box with its edges and corners protected, then each node
// takes a quarter of the volume of each incident tetrahedron and Δx its equivalent diameter
// (CMAME 2017 §6). Kept apart from
// the 2D mesher because Mesh_3 is slow to compile; CGAL is included here only.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/make_mesh_3.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "geometry/mesh_points.hpp"

namespace dhpd::geometry {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Surface = CGAL::Surface_mesh<Kernel::Point_3>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, Surface>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

/// The box as a closed triangle surface, outward oriented.
Surface box_surface(const Box& box) {
  Surface s;
  Surface::Vertex_index v[8];
  for (int k = 0; k < 8; ++k)
    v[k] = s.add_vertex(Kernel::Point_3((k & 1) ? box.max[0] : box.min[0],
                                        (k & 2) ? box.max[1] : box.min[1],
                                        (k & 4) ? box.max[2] : box.min[2]));
  // Each face as a quad in counter-clockwise order seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.add_face(v[q[0]], v[q[1]], v[q[2]]);
    s.add_face(v[q[0]], v[q[2]], v[q[3]]);
  }
  return s;
}

/// The size field h(x) in the form Mesh_3 asks of a sizing field.
struct SizeField {
  using FT = Kernel::FT;
  using Point_3 = Tr::Bare_point;
  using Index = Domain::Index;
  MeshSize size;
  FT operator()(const Point_3& p, const int, const Index&) const {
    return size.at({CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
  }
};

Vec3 to_vec(const Tr::Weighted_point& p) {
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

PointSet lump_volumes(const C3t3& c3t3, int material, int part, PointSize rule) {
  const Tr& tr = c3t3.triangulation();
  std::map<Tr::Vertex_handle, std::size_t> index;
  PointSet out;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Vec3 x[4];
    for (int k = 0; k < 4; ++k) {
      x[k] = to_vec(tr.point(c, k));
      if (index.emplace(c->vertex(k), out.size()).second) {
        out.position.push_back(x[k]);
        out.cell_measure.push_back(0.0);
      }
    }
    const double share = std::abs(dot(cross(x[1] - x[0], x[2] - x[0]), x[3] - x[0])) / 24.0;
    for (int k = 0; k < 4; ++k) out.cell_measure[index.at(c->vertex(k))] += share;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    out.spacing.push_back(point_size(out.cell_measure[i], 3, rule));
    out.material.push_back(material);
    out.part.push_back(part);
  }
  return out;
}

}  // namespace

PointSet mesh_box_3d(const Box& box, const MeshSize& size, int material, int part, PointSize rule) {
  if (!(size.size > 0.0) || !(size.rate >= 0.0))
    throw std::invalid_argument("the mesh size must be > 0 and its grading rate >= 0");
  Domain domain(box_surface(box));
  domain.detect_features();
  namespace params = CGAL::parameters;
  const SizeField field{size};
  const Criteria criteria(params::edge_size = field, params::facet_angle = 25,
                          params::facet_size = field, params::cell_radius_edge_ratio = 3,
                          params::cell_size = field);
  const C3t3 c3t3 =
      CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_perturb(), params::no_exude());
  return lump_volumes(c3t3, material, part, rule);
}

}  // namespace dhpd::geometry
