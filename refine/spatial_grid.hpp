// An incrementally updatable fixed-radius search over reference positions: one hashed cell grid
// per power-of-two spacing class (cell = ratio × that class's spacing), so a query scans a few
// cells of every class whatever the mix of resolutions. Refinement events insert children and
// remove parents in O(1) each; the from-scratch build uses the k-d tree (neighbor_search.hpp).
#pragma once
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "geometry/vec.hpp"

namespace dhpd::refine {

class SpatialGrid {
 public:
  /// `dim` axes are searched; `base_spacing` and `ratio` fix the cell sizes (cell of the class of
  /// spacing s ≈ ratio × s, rounded to base_spacing × 2^k).
  SpatialGrid(int dim, double base_spacing, double ratio);
  double base_spacing() const { return base_; }

  void insert(std::int32_t i, const geometry::Vec3& x, double spacing);
  /// Removes i (no-op when absent).
  void remove(std::int32_t i);
  bool contains(std::int32_t i) const {
    return static_cast<std::size_t>(i) < where_.size() && where_[i].level != kAbsent;
  }
  /// Follows a renumbering that moved a few slots: slot moved[t] now holds the particle that was
  /// at source[t] (the same particles and positions; queries then answer as a new grid would).
  void move_slots(const std::vector<std::int32_t>& moved, const std::vector<std::int32_t>& source);
  /// Every j ≠ skip with |X_j − x|² < radius² (the k-d tree's predicate), ascending, into `out`.
  void within(const geometry::Vec3& x, double radius, std::vector<std::int32_t>& out,
              std::int32_t skip = -1) const;

 private:
  static constexpr int kAbsent = -1000;
  struct Entry {
    geometry::Vec3 x{0, 0, 0};
    int level = kAbsent;
    std::int64_t key = 0, block = 0;
  };
  /// A spacing class k: cells of ratio × base / 2^k, and the occupied cells grouped by the cells
  /// of class 0 they lie in (a block: 2^k cells per axis), so that a wide query of a fine class
  /// visits the occupied cells of a few blocks instead of (2 radius / cell)^dim mostly empty ones.
  struct Level {
    double cell = 0.0;
    int shift = 0;  ///< k: cell coordinates >> shift are block coordinates
    std::unordered_map<std::int64_t, std::vector<std::int32_t>> cells;
    std::unordered_map<std::int64_t, std::vector<std::int64_t>> blocks;  ///< block -> cells
  };
  int level_of(double spacing) const;
  Level& level(int k);
  void cell_of(const Level& l, const geometry::Vec3& x, std::int64_t c[3]) const;
  /// Appends to `out` every entry of the cell `key` strictly within the radius of x.
  void scan(const Level& l, std::int64_t key, const geometry::Vec3& x, double r2,
            std::vector<std::int32_t>& out, std::int32_t skip) const;

  int dim_;
  double base_, ratio_;
  std::map<int, Level> levels_;
  std::vector<Entry> where_;
};

}  // namespace dhpd::refine
