// Hashed cell grids per spacing class (see spatial_grid.hpp).
#include "refine/spatial_grid.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

namespace dhpd::refine {

namespace {
constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;

std::int64_t cell_coordinate(double x, double cell) {
  return static_cast<std::int64_t>(std::floor(x / cell));
}

/// 21 bits per axis; far-apart cells that share a key only add candidates (all are
/// distance-checked, duplicates removed).
std::int64_t pack(std::int64_t cx, std::int64_t cy, std::int64_t cz) {
  return ((cx & kMask) << 42) | ((cy & kMask) << 21) | (cz & kMask);
}
}  // namespace

SpatialGrid::SpatialGrid(int dim, double base_spacing, double ratio)
    : dim_(dim), base_(base_spacing), ratio_(ratio) {}

int SpatialGrid::level_of(double spacing) const {
  return static_cast<int>(std::lround(std::log2(base_ / spacing)));
}

SpatialGrid::Level& SpatialGrid::level(int k) {
  auto& l = levels_[k];
  if (l.cell == 0.0) {
    l.cell = ratio_ * base_ * std::ldexp(1.0, -k);
    l.shift = std::max(k, 0);
  }
  return l;
}

void SpatialGrid::cell_of(const Level& l, const geometry::Vec3& x, std::int64_t c[3]) const {
  c[0] = c[1] = c[2] = 0;
  for (int a = 0; a < dim_; ++a) c[a] = cell_coordinate(x[a], l.cell);
}

void SpatialGrid::insert(std::int32_t i, const geometry::Vec3& x, double spacing) {
  remove(i);
  if (where_.size() <= static_cast<std::size_t>(i)) where_.resize(static_cast<std::size_t>(i) + 1);
  const int k = level_of(spacing);
  auto& l = level(k);
  std::int64_t c[3];
  cell_of(l, x, c);
  auto& e = where_[static_cast<std::size_t>(i)];
  // Arithmetic shifts floor negative coordinates too: a cell lies in exactly one block.
  e = {x, k, pack(c[0], c[1], c[2]), pack(c[0] >> l.shift, c[1] >> l.shift, c[2] >> l.shift)};
  auto& cell = l.cells[e.key];
  if (cell.empty()) l.blocks[e.block].push_back(e.key);
  cell.push_back(i);
}

void SpatialGrid::remove(std::int32_t i) {
  if (!contains(i)) return;
  auto& e = where_[static_cast<std::size_t>(i)];
  auto& l = levels_.at(e.level);
  auto& cell = l.cells.at(e.key);
  cell.erase(std::find(cell.begin(), cell.end(), i));
  if (cell.empty()) {
    l.cells.erase(e.key);
    auto& block = l.blocks.at(e.block);
    block.erase(std::find(block.begin(), block.end(), e.key));
    if (block.empty()) l.blocks.erase(e.block);
  }
  e.level = kAbsent;
}

void SpatialGrid::move_slots(const std::vector<std::int32_t>& moved,
                             const std::vector<std::int32_t>& source) {
  std::vector<Entry> from(moved.size());
  std::unordered_map<std::int32_t, std::int32_t> new_slot;
  std::vector<std::pair<int, std::int64_t>> cells;  // (class, key) of every moved particle
  for (std::size_t t = 0; t < moved.size(); ++t) {
    const auto s = static_cast<std::size_t>(source[t]);
    from[t] = s < where_.size() ? where_[s] : Entry{};
    new_slot[source[t]] = moved[t];
    if (from[t].level != kAbsent) cells.emplace_back(from[t].level, from[t].key);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  for (const auto& [k, key] : cells)  // each cell once: every id in it renamed once
    for (auto& id : levels_.at(k).cells.at(key)) {
      const auto it = new_slot.find(id);
      if (it != new_slot.end()) id = it->second;
    }
  for (std::size_t t = 0; t < moved.size(); ++t) {
    const auto m = static_cast<std::size_t>(moved[t]);
    if (where_.size() <= m) where_.resize(m + 1);
    where_[m] = from[t];
  }
}

void SpatialGrid::scan(const Level& l, std::int64_t key, const geometry::Vec3& x, double r2,
                       std::vector<std::int32_t>& out, std::int32_t skip) const {
  const auto it = l.cells.find(key);
  if (it == l.cells.end()) return;
  for (const auto j : it->second) {
    const auto& y = where_[static_cast<std::size_t>(j)].x;
    double d2 = 0.0;
    for (int a = 0; a < dim_; ++a) {
      const double d = x[a] - y[a];
      d2 += d * d;
    }
    if (d2 < r2 && j != skip) out.push_back(j);
  }
}

void SpatialGrid::within(const geometry::Vec3& x, double radius, std::vector<std::int32_t>& out,
                         std::int32_t skip) const {
  out.clear();
  const double r2 = radius * radius;
  constexpr double kMostCellsToVisit = 64;
  for (const auto& [k, l] : levels_) {
    std::int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    double cells = 1;
    for (int a = 0; a < dim_; ++a) {
      lo[a] = cell_coordinate(x[a] - radius, l.cell);
      hi[a] = cell_coordinate(x[a] + radius, l.cell);
      cells *= static_cast<double>(hi[a] - lo[a] + 1);
    }
    if (cells <= kMostCellsToVisit || l.shift == 0) {
      for (auto cx = lo[0]; cx <= hi[0]; ++cx)
        for (auto cy = lo[1]; cy <= hi[1]; ++cy)
          for (auto cz = lo[2]; cz <= hi[2]; ++cz) scan(l, pack(cx, cy, cz), x, r2, out, skip);
      continue;
    }
    // A wide query of a fine class: the occupied cells of the blocks in range.
    for (auto bx = lo[0] >> l.shift; bx <= hi[0] >> l.shift; ++bx)
      for (auto by = lo[1] >> l.shift; by <= hi[1] >> l.shift; ++by)
        for (auto bz = lo[2] >> l.shift; bz <= hi[2] >> l.shift; ++bz) {
          const auto block = l.blocks.find(pack(bx, by, bz));
          if (block == l.blocks.end()) continue;
          for (const auto key : block->second) scan(l, key, x, r2, out, skip);
        }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace dhpd::refine
