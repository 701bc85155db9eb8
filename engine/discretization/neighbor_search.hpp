// Fixed-radius neighbour search with a per-query radius (nanoflann k-d tree, wrapped here only).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd {

class NeighborSearch {
 public:
  /// Builds a k-d tree over the first `dim` components of `points` (kept by reference).
  NeighborSearch(const VectorArray& points, int dim);
  ~NeighborSearch();
  NeighborSearch(const NeighborSearch&) = delete;
  NeighborSearch& operator=(const NeighborSearch&) = delete;

  /// Indices j ≠ i with |X_j − X_i| ≤ radius, sorted ascending, appended to `out` (cleared first).
  void within(std::size_t i, double radius, std::vector<std::int32_t>& out) const;
  /// Indices j with |X_j − x| ≤ radius (x need not be one of the points), sorted ascending.
  void around(const double x[3], double radius, std::vector<std::int32_t>& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dhpd
