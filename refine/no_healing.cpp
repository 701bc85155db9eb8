// The no-healing rule for the bonds of a new generation (docs/theory.md §13.5; IJNME 2016 §5.3).
#include "refine/no_healing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "engine/physics/bond_law.hpp"
#include "geometry/predicates.hpp"

namespace dhpd::refine {

using geometry::dot;
using geometry::norm;
using geometry::Vec3;

Vec3 OldGeneration::position(std::int32_t x) const {
  if (parent_slot) {
    const auto k = (*parent_slot)[static_cast<std::size_t>(x)];
    if (k >= 0) return point_of(parents->reference_position, static_cast<std::size_t>(k));
  }
  return point_of(particles.reference_position, static_cast<std::size_t>(x));
}

bool segments_cross_properly(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Relative tolerance: collinear or touching configurations (lattice points in a row, shared
  // endpoints) are not proper crossings even when round-off gives them a sign.
  const double tol = 1e-9 * norm(b - a) * norm(d - c);
  const double o1 = geometry::orient2d(a, b, c), o2 = geometry::orient2d(a, b, d);
  const double o3 = geometry::orient2d(c, d, a), o4 = geometry::orient2d(c, d, b);
  auto opposite = [tol](double x, double y) {
    return (x > tol && y < -tol) || (x < -tol && y > tol);
  };
  return opposite(o1, o2) && opposite(o3, o4);
}

bool segment_passes_through_tube(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                                 double tube) {
  // Closest points of the two lines: a + s (b − a) and c + t (d − c).
  const Vec3 u = b - a, v = d - c, w = a - c;
  const double uu = dot(u, u), uv = dot(u, v), vv = dot(v, v), uw = dot(u, w), vw = dot(v, w);
  const double den = uu * vv - uv * uv;
  if (!(den > 1e-12 * uu * vv)) return false;  // parallel: no single crossing point
  const double s = (uv * vw - vv * uw) / den, t = (uu * vw - uv * uw) / den;
  constexpr double eps = 1e-9;
  if (s <= eps || s >= 1.0 - eps || t <= eps || t >= 1.0 - eps) return false;
  return norm((a + s * u) - (c + t * v)) < tube;
}

OldSegments::OldSegments(const OldGeneration& old, std::vector<std::int32_t> owners)
    : old_(old), owners_(std::move(owners)), dim_(old.particles.dim()) {
  const auto& b = old.bonds;
  for (const auto i : owners_)
    for_each_own_bond(b, static_cast<std::size_t>(i), [&](std::int64_t k, std::size_t) {
      max_length_ = std::max(max_length_, b.length(k));
    });
  std::vector<std::pair<std::int32_t, std::int32_t>> broken;
  for (const auto i : owners_)
    for_each_own_bond(b, static_cast<std::size_t>(i), [&](std::int64_t k, std::size_t j) {
      if (!b.own_intact(k)) broken.emplace_back(i, static_cast<std::int32_t>(j));
    });
  broken_ = binned(broken);
}

OldSegments::Bins OldSegments::binned(
    const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs) const {
  Bins bins;
  if (pairs.empty()) return bins;
  auto midpoint = [&](const std::pair<std::int32_t, std::int32_t>& e) {
    return 0.5 * (old_.position(e.first) + old_.position(e.second));
  };
  const auto n = static_cast<std::int64_t>(pairs.size());
  const bool parallel = n >= 16384;  // the per-pair passes in parallel (min, max: any order)
  const Vec3 first = midpoint(pairs[0]);
  double lx = first[0], ly = first[1], lz = first[2], hx = lx, hy = ly, hz = lz;
#pragma omp parallel for schedule(static) if (parallel) reduction(min           \
                                                                  : lx, ly, lz) \
    reduction(max                                                               \
              : hx, hy, hz)
  for (std::int64_t k = 0; k < n; ++k) {
    const Vec3 m = midpoint(pairs[k]);
    lx = std::min(lx, m[0]), ly = std::min(ly, m[1]), lz = std::min(lz, m[2]);
    hx = std::max(hx, m[0]), hy = std::max(hy, m[1]), hz = std::max(hz, m[2]);
  }
  const Vec3 low{lx, ly, lz}, high{hx, hy, hz};
  // Cells a quarter of the longest bond wide (a query then scans about the volume a crossing
  // bond's midpoint can lie in), or wider where that would give more than about four cells per
  // segment (midpoints spread over a large body): the cell width changes the work, not the count.
  double volume = 1.0;
  for (int a = 0; a < dim_; ++a) volume *= high[a] - low[a] + 0.25 * max_length_;
  bins.cell = std::max(0.25 * max_length_,
                       std::pow(volume / (4.0 * static_cast<double>(pairs.size())), 1.0 / dim_));
  for (int a = 0; a < 3; ++a) {
    bins.lo[a] = a < dim_ ? static_cast<std::int64_t>(std::floor(low[a] / bins.cell)) : 0;
    bins.n[a] =
        a < dim_ ? static_cast<std::int64_t>(std::floor(high[a] / bins.cell)) - bins.lo[a] + 1 : 1;
  }
  std::vector<std::int64_t> cell_of(pairs.size());  // per pair, its cell, then its place
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t k = 0; k < n; ++k) {
    const Vec3 m = midpoint(pairs[k]);
    std::int64_t cell[3] = {0, 0, 0};
    for (int a = 0; a < dim_; ++a)
      cell[a] = static_cast<std::int64_t>(std::floor(m[a] / bins.cell)) - bins.lo[a];
    cell_of[k] = (cell[2] * bins.n[1] + cell[1]) * bins.n[0] + cell[0];
  }
  bins.first.assign(static_cast<std::size_t>(bins.n[0] * bins.n[1] * bins.n[2] + 1), 0);
  for (const auto c : cell_of) ++bins.first[static_cast<std::size_t>(c + 1)];
  for (std::size_t k = 1; k < bins.first.size(); ++k) bins.first[k] += bins.first[k - 1];
  bins.segments.resize(pairs.size());
  bins.boxes.resize(pairs.size());
  auto next = bins.first;
  for (auto& c : cell_of) c = next[static_cast<std::size_t>(c)]++;
  constexpr float inf = std::numeric_limits<float>::infinity();
#pragma omp parallel for schedule(static) if (parallel)
  for (std::int64_t k = 0; k < n; ++k) {  // each pair to its own place
    const auto at = static_cast<std::size_t>(cell_of[k]);
    bins.segments[at] = Segment{pairs[k].first, pairs[k].second};
    const Vec3 c = old_.position(pairs[k].first), d = old_.position(pairs[k].second);
    for (int a = 0; a < 3; ++a) {
      bins.boxes[at][a] = std::nextafter(static_cast<float>(std::min(c[a], d[a])), -inf);
      bins.boxes[at][3 + a] = std::nextafter(static_cast<float>(std::max(c[a], d[a])), inf);
    }
  }
  return bins;
}

std::size_t OldSegments::count(const Bins& bins, const Vec3& a, const Vec3& b, std::int32_t skip,
                               double tube, std::size_t enough) const {
  // A segment with a point in the box of a–b grown by the tube has its midpoint in that box grown
  // by half the longest bond more; one whose own box misses the first cannot cross.
  Vec3 box_lo{0, 0, 0}, box_hi{0, 0, 0};
  std::int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int d = 0; d < dim_; ++d) {
    box_lo[d] = std::min(a[d], b[d]) - tube, box_hi[d] = std::max(a[d], b[d]) + tube;
    lo[d] = static_cast<std::int64_t>(std::floor((box_lo[d] - 0.5 * max_length_) / bins.cell));
    hi[d] = static_cast<std::int64_t>(std::floor((box_hi[d] + 0.5 * max_length_) / bins.cell));
  }
  for (int d = 0; d < 3; ++d) {
    lo[d] = std::max(lo[d], bins.lo[d]) - bins.lo[d];
    hi[d] = std::min(hi[d], bins.lo[d] + bins.n[d] - 1) - bins.lo[d];
    if (hi[d] < lo[d]) return 0;
  }
  // A box that misses the query's cannot cross it; the float boxes contain the segments' own.
  auto misses = [&](const std::array<float, 6>& box) {
    for (int d = 0; d < dim_; ++d)
      if (box[3 + d] < box_lo[d] || box[d] > box_hi[d]) return true;
    return false;
  };
  std::size_t n = 0;
  for (auto cz = lo[2]; cz <= hi[2]; ++cz)
    for (auto cy = lo[1]; cy <= hi[1]; ++cy) {
      const auto row = (cz * bins.n[1] + cy) * bins.n[0];
      const auto first = bins.first[static_cast<std::size_t>(row + lo[0])];
      const auto last = bins.first[static_cast<std::size_t>(row + hi[0] + 1)];
      for (auto k = first; k < last; ++k) {  // the cells lo[0]..hi[0] of this row, one run
        if (misses(bins.boxes[static_cast<std::size_t>(k)])) continue;
        const auto& s = bins.segments[static_cast<std::size_t>(k)];
        if (s.owner == skip || s.neighbor == skip) continue;
        const Vec3 c = old_.position(s.owner), d = old_.position(s.neighbor);
        n += dim_ == 2 ? segments_cross_properly(a, b, c, d)
                       : segment_passes_through_tube(a, b, c, d, tube);
        if (n >= enough) return n;
      }
    }
  return n;
}

OldSegments::Crossings OldSegments::crossing(const Vec3& a, const Vec3& b, std::int32_t skip,
                                             double tube, bool count_all) const {
  Crossings out;
  if (broken_.empty() || dim_ == 1) return out;
  // Without count_all only whether a broken bond crosses matters: the first one settles it.
  out.broken = count(broken_, a, b, skip, tube, count_all ? kEvery : 1);
  if (!count_all || out.broken == 0) return out;
  std::call_once(all_built_, [&] {
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    for (const auto i : owners_)
      for_each_own_bond(old_.bonds, static_cast<std::size_t>(i), [&](std::int64_t, std::size_t j) {
        pairs.emplace_back(i, static_cast<std::int32_t>(j));
      });
    all_ = binned(pairs);
  });
  // Only whether the broken ones are more than half matters: counting stops at twice them.
  out.all = count(all_, a, b, skip, tube, 2 * out.broken);
  return out;
}

namespace {

enum class PairState { None, Intact, Broken };

/// State of the previous bonds between P and Q: P→Q only when `one_way`, else P→Q and Q→P.
PairState pair_state(const BondRows& b, std::int32_t P, std::int32_t Q, bool one_way) {
  bool found = false, broken = false;
  const auto k = b.find(static_cast<std::size_t>(P), Q);
  if (k >= 0) {  // entry Q of row P: P→Q is its own bond, Q→P its dual
    if (b.has_own(k)) found = true, broken = broken || !b.own_intact(k);
    if (!one_way && b.has_dual(k)) found = true, broken = broken || !b.dual_intact(k);
  }
  return !found ? PairState::None : (broken ? PairState::Broken : PairState::Intact);
}

}  // namespace

bool starts_broken(const OldGeneration& old, const OldSegments& segments, const Vec3& xi,
                   const Vec3& xj, std::int32_t P, std::int32_t Q, bool both_unsplit, double tube) {
  const PairState state = P == Q ? PairState::None : pair_state(old.bonds, P, Q, both_unsplit);
  if (state != PairState::None) return state == PairState::Broken;
  const auto c = segments.crossing(xi, xj, P == Q ? P : -1, tube, P == Q);
  return P == Q ? 2 * c.broken > c.all : c.broken > 0;
}

bool starts_overstretched(const ParticleStore& p, std::size_t owner, std::size_t neighbor,
                          double inverse_length, double owner_critical_stretch) {
  return !p.no_fail[owner] &&
         bond_law::reaches_critical_stretch(
             bond_law::stretch_ratio2(bond_law::squared_length(p, owner, neighbor), inverse_length),
             owner_critical_stretch);
}

std::int64_t apply_no_healing(BondRows& bonds, const ParticleStore& p,
                              const std::vector<std::int32_t>& previous,
                              const std::vector<std::uint8_t>& born, const BondRows& old_bonds,
                              const ParticleStore& old_p) {
  const OldGeneration old{old_bonds, old_p};
  std::vector<std::int32_t> all(old_p.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
  const OldSegments segments(old, std::move(all));
  for (std::size_t i = 0; i < bonds.particles(); ++i)  // everything intact first
    for (auto k = bonds.begin(i); k < bonds.end(i); ++k)
      bonds.flags[k] =
          static_cast<std::uint8_t>(bonds.flags[k] | (bonds.has_own(k) ? kOwnIntact : 0) |
                                    (bonds.has_dual(k) ? kDualIntact : 0));
  if (!segments.any_broken()) return 0;
  std::int64_t count = 0;
  const auto& X = p.reference_position;
  for (std::size_t i = 0; i < bonds.particles(); ++i)
    for_each_own_bond(bonds, i, [&](std::int64_t k, std::size_t j) {
      const bool cut = starts_broken(
          old, segments, {X[0][i], X[1][i], X[2][i]}, {X[0][j], X[1][j], X[2][j]}, previous[i],
          previous[j], !born[i] && !born[j], 0.5 * std::min(p.spacing[i], p.spacing[j]));
      if (!cut) return;
      // The bond's own side in row i and its dual side in row j.
      bonds.flags[k] = static_cast<std::uint8_t>(bonds.flags[k] & ~kOwnIntact);
      const auto d = bonds.find(j, static_cast<std::int32_t>(i));
      bonds.flags[d] = static_cast<std::uint8_t>(bonds.flags[d] & ~kDualIntact);
      ++count;
    });
  return count;
}

}  // namespace dhpd::refine
