// Point generation: a cell-centred lattice fills each body part; later parts win where they
// overlap.
#pragma once
#include <cstdint>
#include <vector>

#include "geometry/shapes.hpp"

namespace dhpd::geometry {

struct LatticePart {
  Box box;
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

/// Number of cells of `part` along each axis (round to nearest so that max−min = n·spacing is
/// exact).
std::array<std::int64_t, 3> lattice_cells(const LatticePart& part, int dim);

/// Points at min + (i + ½)·spacing; a point inside a later part's box is dropped (that part wins).
PointSet fill_lattice(const std::vector<LatticePart>& parts, int dim);

/// Permutation that sorts points along a Morton (Z-order) curve, so neighbours sit close in memory.
std::vector<std::int32_t> morton_order(const std::vector<Vec3>& points, int dim);

/// Apply a permutation (new index k holds old index perm[k]) to every array of the point set.
PointSet permuted(const PointSet& points, const std::vector<std::int32_t>& perm);

}  // namespace dhpd::geometry
