// Degenerate and coincident points, found with a sorted cell key (no tree needed).
#include "geometry/point_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace dhpd::geometry {
namespace {

using Key = std::array<std::int64_t, 3>;

Key cell_of(const Vec3& x, double cell, int dim) {
  Key k{0, 0, 0};
  for (int a = 0; a < dim; ++a) k[a] = static_cast<std::int64_t>(std::floor(x[a] / cell));
  return k;
}

double distance(const Vec3& a, const Vec3& b, int dim) {
  double d2 = 0.0;
  for (int k = 0; k < dim; ++k) d2 += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(d2);
}

}  // namespace

std::optional<std::size_t> first_degenerate_point(const PointSet& points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!(std::isfinite(points.cell_measure[i]) && points.cell_measure[i] > 0.0 &&
          std::isfinite(points.spacing[i]) && points.spacing[i] > 0.0))
      return i;
  return std::nullopt;
}

std::optional<std::pair<std::size_t, std::size_t>> first_coincident_pair(const PointSet& points,
                                                                         int dim, double relative) {
  const std::size_t n = points.size();
  if (n < 2) return std::nullopt;
  // Cells as wide as the smallest spacing: a coincident pair lies in one cell or two adjacent.
  const double cell = *std::min_element(points.spacing.begin(), points.spacing.end());
  std::vector<Key> key(n);
  for (std::size_t i = 0; i < n; ++i) key[i] = cell_of(points.position[i], cell, dim);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return key[a] != key[b] ? key[a] < key[b] : a < b;
  });
  std::optional<std::pair<std::size_t, std::size_t>> best;
  auto consider = [&](std::size_t i, std::size_t j) {
    if (i == j) return;
    const auto pair = std::minmax(i, j);
    const double limit = relative * std::min(points.spacing[i], points.spacing[j]);
    if (distance(points.position[i], points.position[j], dim) >= limit) return;
    if (!best || pair.second < best->second ||
        (pair.second == best->second && pair.first < best->first))
      best = pair;
  };
  const int reach_y = dim >= 2 ? 1 : 0, reach_z = dim >= 3 ? 1 : 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -reach_y; dy <= reach_y; ++dy)
        for (int dz = -reach_z; dz <= reach_z; ++dz) {
          const Key k{key[i][0] + dx, key[i][1] + dy, key[i][2] + dz};
          auto lo = std::lower_bound(order.begin(), order.end(), k,
                                     [&](std::size_t a, const Key& v) { return key[a] < v; });
          for (; lo != order.end() && key[*lo] == k; ++lo) consider(i, *lo);
        }
  return best;
}

}  // namespace dhpd::geometry
