// Cell-centred lattice fill with part overrides, and Morton ordering of points.
#include "geometry/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dhpd::geometry {

std::array<std::int64_t, 3> lattice_cells(const LatticePart& part, int dim) {
  std::array<std::int64_t, 3> n{1, 1, 1};
  const Box box = part.shape.bounds(dim);
  for (int a = 0; a < dim; ++a) {
    const double cells = (box.max[a] - box.min[a]) / part.spacing;
    // A part whose length is a whole number of cells (to round-off) gets exactly that many.
    const double rounded = std::round(cells);
    n[a] = std::abs(cells - rounded) < 1e-9 * std::max(1.0, cells)
               ? static_cast<std::int64_t>(rounded)
               : static_cast<std::int64_t>(std::floor(cells));
    n[a] = std::max<std::int64_t>(n[a], 1);
  }
  return n;
}

PointSet fill_lattice(const std::vector<LatticePart>& parts, int dim) {
  PointSet out;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& part = parts[p];
    const auto n = lattice_cells(part, dim);
    const Box box = part.shape.bounds(dim);
    const double measure = std::pow(part.spacing, dim);
    for (std::int64_t k = 0; k < n[2]; ++k)
      for (std::int64_t j = 0; j < n[1]; ++j)
        for (std::int64_t i = 0; i < n[0]; ++i) {
          const std::int64_t idx[3] = {i, j, k};
          Vec3 x{0, 0, 0};
          for (int a = 0; a < dim; ++a)
            x[a] = box.min[a] + (static_cast<double>(idx[a]) + 0.5) * part.spacing;
          if (!part.shape.contains(x, dim)) continue;
          bool overridden = false;
          for (std::size_t q = p + 1; q < parts.size() && !overridden; ++q)
            overridden = parts[q].shape.contains(x, dim);
          if (overridden) continue;
          out.position.push_back(x);
          out.cell_measure.push_back(measure);
          out.spacing.push_back(part.spacing);
          out.material.push_back(part.material);
          out.part.push_back(static_cast<int>(p));
        }
  }
  return out;
}

std::vector<std::size_t> assign_materials(PointSet& points,
                                          const std::vector<MaterialRegion>& regions, int dim) {
  std::vector<std::size_t> selected(regions.size(), 0);
  for (std::size_t r = 0; r < regions.size(); ++r)
    for (std::size_t i = 0; i < points.size(); ++i)
      if (regions[r].region.contains(points.position[i], dim)) {
        points.material[i] = regions[r].material;
        ++selected[r];
      }
  return selected;
}

namespace {
std::uint64_t spread_bits(std::uint64_t v, int dim) {
  // Interleave the low bits of v with (dim − 1) zero bits between them.
  std::uint64_t r = 0;
  const int bits = dim == 3 ? 21 : (dim == 2 ? 32 : 63);
  for (int b = 0; b < bits; ++b) r |= ((v >> b) & 1ULL) << (b * dim);
  return r;
}
}  // namespace

std::vector<std::int32_t> morton_order(const std::vector<Vec3>& points, int dim) {
  std::vector<std::int32_t> perm(points.size());
  std::iota(perm.begin(), perm.end(), 0);
  if (points.empty()) return perm;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  for (int a = 0; a < dim; ++a) {
    lo[a] = std::numeric_limits<double>::max();
    hi[a] = std::numeric_limits<double>::lowest();
  }
  for (const auto& p : points)
    for (int a = 0; a < dim; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  const int bits = dim == 3 ? 21 : (dim == 2 ? 32 : 63);
  const double cells = std::ldexp(1.0, std::min(bits, 52)) - 1.0;
  std::vector<std::uint64_t> code(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < dim; ++a) {
      const double extent = hi[a] - lo[a];
      const double t = extent > 0 ? (points[i][a] - lo[a]) / extent : 0.0;
      code[i] |= spread_bits(static_cast<std::uint64_t>(t * cells), dim) << a;
    }
  std::stable_sort(perm.begin(), perm.end(),
                   [&](std::int32_t a, std::int32_t b) { return code[a] < code[b]; });
  return perm;
}

PointSet permuted(const PointSet& points, const std::vector<std::int32_t>& perm) {
  PointSet out;
  const std::size_t n = perm.size();
  out.position.resize(n);
  out.cell_measure.resize(n);
  out.spacing.resize(n);
  out.material.resize(n);
  out.part.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto o = static_cast<std::size_t>(perm[k]);
    out.position[k] = points.position[o];
    out.cell_measure[k] = points.cell_measure[o];
    out.spacing[k] = points.spacing[o];
    out.material[k] = points.material[o];
    out.part[k] = points.part[o];
  }
  return out;
}

}  // namespace dhpd::geometry
