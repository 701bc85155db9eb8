// Point generation: a cell-centred lattice fills the bounding box of each body part and keeps the
// points inside the part's shape; later parts win where they overlap.
#pragma once
#include <cstdint>
#include <vector>

#include "geometry/shapes.hpp"

namespace dhpd::geometry {

struct LatticePart {
  Shape shape;  ///< must be bounded
  double spacing = 0.0;
  int material = 0;
};

/// Points with their cell measure (length, area or volume of the cell: spacing^dim).
struct PointSet {
  std::vector<Vec3> position;
  std::vector<double> cell_measure;
  std::vector<double> spacing;
  std::vector<int> material;
  std::vector<int> part;
  std::size_t size() const { return position.size(); }
};

/// A region of a body that takes another material (inclusions, CMAME 2017 §5.2).
struct MaterialRegion {
  Shape region;
  int material = 0;
};

/// Number of cells of the part's bounding box along each axis (round to nearest so that
/// max−min = n·spacing is exact).
std::array<std::int64_t, 3> lattice_cells(const LatticePart& part, int dim);

/// Points at min + (i + ½)·spacing of each part's bounding box that lie inside its shape; a point
/// inside a later part's shape is dropped (that part wins).
PointSet fill_lattice(const std::vector<LatticePart>& parts, int dim);

/// Gives the points inside each region that region's material; later regions win. Returns the
/// number of points each region selected.
std::vector<std::size_t> assign_materials(PointSet& points,
                                          const std::vector<MaterialRegion>& regions, int dim);

/// Permutation that sorts points along a Morton (Z-order) curve, so neighbours sit close in memory.
std::vector<std::int32_t> morton_order(const std::vector<Vec3>& points, int dim);

/// Apply a permutation (new index k holds old index perm[k]) to every array of the point set.
PointSet permuted(const PointSet& points, const std::vector<std::int32_t>& perm);

}  // namespace dhpd::geometry
