// Splitting by the field registry and the no-healing rule (dhpd.md §8; IJNME 2016 §5.3).
#include "engine/refinement_event.hpp"

#include "geometry/predicates.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>

#include "engine/errors.hpp"

namespace dhpd {

using geometry::norm;
using geometry::Vec3;
using geometry::operator+;
using geometry::operator-;
using geometry::operator*;

namespace {

Vec3 point(const VectorArray& x, std::size_t i) {
  return {x[0][i], x[1][i], x[2][i]};
}

/// Copies (kept particles, Copy) or maps (DivideByChildren, Reset) every registered field; the
/// FromPattern fields are copied here and set by `set_pattern_fields`.
void map_fields(const ParticleStore& old_p, ParticleStore& p, const std::vector<std::int32_t>& prev,
                std::size_t kept, double children_per_parent) {
  // fields() hands out mutable pointers; the old store is only read through them.
  auto old_fields = const_cast<ParticleStore&>(old_p).fields();
  auto new_fields = p.fields();
  for (std::size_t f = 0; f < new_fields.size(); ++f) {
    const SplitRule rule = new_fields[f].split;
    std::visit(
        [&](auto* dst) {
          using T = std::remove_pointer_t<decltype(dst)>;
          const T* src = std::get<T*>(old_fields[f].data);
          auto one = [&](auto& out, const auto& in) {
            using V = typename std::remove_reference_t<decltype(out)>::value_type;
            for (std::size_t k = 0; k < prev.size(); ++k) {
              V v = in[static_cast<std::size_t>(prev[k])];
              if (k >= kept && rule == SplitRule::Reset) v = V{};
              if constexpr (std::is_floating_point_v<V>)
                if (k >= kept && rule == SplitRule::DivideByChildren) v /= children_per_parent;
              out[k] = v;
            }
          };
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (int a = 0; a < 3; ++a) one((*dst)[a], (*src)[a]);
          } else {
            one(*dst, *src);
          }
        },
        new_fields[f].data);
  }
}

/// The FromPattern fields of the children; throws when a field declared FromPattern has no rule
/// here (so a new field cannot be forgotten silently).
void set_pattern_fields(const ParticleStore& old_p, ParticleStore& p,
                        const std::vector<std::int32_t>& prev, std::size_t kept,
                        const Section& section, std::int32_t next_id) {
  static constexpr std::string_view handled[] = {
      "reference_position", "spacing", "horizon", "radius", "id", "level", "parent_id", "position"};
  for (const auto& f : p.fields())
    if (f.split == SplitRule::FromPattern &&
        std::find(std::begin(handled), std::end(handled), f.name) == std::end(handled))
      throw EngineError("split: no pattern rule for field '" + std::string(f.name) + "'");
  const std::size_t per_parent = std::size_t{1} << p.dim();
  for (std::size_t k = kept; k < prev.size(); ++k) {
    const auto q = static_cast<std::size_t>(prev[k]);
    const auto offsets = child_offsets(p.dim(), old_p.spacing[q]);
    const auto& off = offsets[(k - kept) % per_parent];
    for (int a = 0; a < 3; ++a) {
      p.reference_position[a][k] = old_p.reference_position[a][q] + off[a];
      p.position[a][k] = p.reference_position[a][k] + p.displacement[a][k];
    }
    p.spacing[k] = 0.5 * old_p.spacing[q];
    p.horizon[k] = 0.5 * old_p.horizon[q];
    p.radius[k] = section.equal_measure_radius(p.volume[k]);
    p.id[k] = next_id + static_cast<std::int32_t>(k - kept);
    p.level[k] = old_p.level[q] + 1;
    p.parent_id[k] = old_p.id[q];
  }
}

}  // namespace

std::vector<Vec3> child_offsets(int dim, double dx) {
  std::vector<Vec3> out;
  const double q = 0.25 * dx;
  for (int c = 0; c < (1 << dim); ++c) {
    Vec3 o{0, 0, 0};
    for (int a = 0; a < dim; ++a) o[a] = (c >> a) & 1 ? q : -q;
    out.push_back(o);
  }
  return out;
}

SplitResult split_particles(const ParticleStore& p, const std::vector<std::int32_t>& parents,
                            const Section& section, std::int32_t next_id) {
  std::vector<std::uint8_t> is_parent(p.size(), 0);
  for (const auto q : parents) {
    if (q < 0 || static_cast<std::size_t>(q) >= p.size())
      throw EngineError("split: parent index out of range");
    if (is_parent[static_cast<std::size_t>(q)]++)
      throw EngineError("split: a parent is listed twice");
  }
  SplitResult r;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!is_parent[i]) r.previous.push_back(static_cast<std::int32_t>(i));
  const std::size_t kept = r.previous.size();
  const std::size_t per_parent = std::size_t{1} << p.dim();
  for (const auto q : parents)
    for (std::size_t c = 0; c < per_parent; ++c) r.previous.push_back(q);
  r.kept = kept;
  r.children = r.previous.size() - kept;
  r.particles = ParticleStore(p.dim());
  r.particles.resize(r.previous.size());
  map_fields(p, r.particles, r.previous, kept, static_cast<double>(per_parent));
  set_pattern_fields(p, r.particles, r.previous, kept, section, next_id);
  return r;
}

namespace {

/// Least-squares gradient G (row-major dim × dim) of u over i's intact own bonds:
/// G = (Σ η ξᵀ)(Σ ξ ξᵀ)⁻¹. False when the bonds do not span the space.
bool displacement_gradient(const ParticleStore& p, const BondList& b, std::size_t i, double G[9]) {
  const int d = p.dim();
  double A[3][6] = {}, B[3][3] = {};
  for (auto k = b.offset[i]; k < b.offset[i + 1]; ++k) {
    if (!b.intact[k]) continue;
    const auto j = static_cast<std::size_t>(b.neighbor[k]);
    double xi[3], eta[3];
    for (int a = 0; a < d; ++a) {
      xi[a] = p.reference_position[a][j] - p.reference_position[a][i];
      eta[a] = p.displacement[a][j] - p.displacement[a][i];
    }
    for (int r = 0; r < d; ++r)
      for (int c = 0; c < d; ++c) A[r][c] += xi[r] * xi[c], B[r][c] += eta[r] * xi[c];
  }
  // Invert A by Gauss-Jordan on [A | I] with partial pivoting.
  double scale = 0.0;
  for (int r = 0; r < d; ++r) A[r][d + r] = 1.0, scale = std::max(scale, A[r][r]);
  for (int c = 0; c < d; ++c) {
    int piv = c;
    for (int r = c + 1; r < d; ++r)
      if (std::abs(A[r][c]) > std::abs(A[piv][c])) piv = r;
    if (!(std::abs(A[piv][c]) > 1e-12 * scale)) return false;
    std::swap(A[c], A[piv]);
    const double inv = 1.0 / A[c][c];
    for (int k = 0; k < 2 * d; ++k) A[c][k] *= inv;
    for (int r = 0; r < d; ++r)
      if (r != c) {
        const double f = A[r][c];
        for (int k = 0; k < 2 * d; ++k) A[r][k] -= f * A[c][k];
      }
  }
  for (int r = 0; r < d; ++r)
    for (int c = 0; c < d; ++c) {
      double g = 0.0;
      for (int k = 0; k < d; ++k) g += B[r][k] * A[k][d + c];
      G[r * 3 + c] = g;
    }
  return true;
}

}  // namespace

void map_displacement(SplitResult& split, StateMapping mapping, const ParticleStore& old_p,
                      const BondList& old_bonds) {
  if (mapping == StateMapping::Copy) return;
  auto& p = split.particles;
  const int d = p.dim();
  const std::size_t per_parent = std::size_t{1} << d;
  double G[9] = {};
  for (std::size_t k = split.kept; k < p.size(); ++k) {
    const auto q = static_cast<std::size_t>(split.previous[k]);
    if ((k - split.kept) % per_parent == 0 && !displacement_gradient(old_p, old_bonds, q, G))
      std::fill(std::begin(G), std::end(G), 0.0);
    for (int r = 0; r < d; ++r) {
      double du = 0.0;
      for (int c = 0; c < d; ++c)
        du += G[r * 3 + c] * (p.reference_position[c][k] - old_p.reference_position[c][q]);
      p.displacement[r][k] = old_p.displacement[r][q] + du;
      p.position[r][k] = p.reference_position[r][k] + p.displacement[r][k];
    }
  }
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

namespace {

enum class PairState { None, Intact, Broken };

/// State of the previous bonds between P and Q: P→Q only when `one_way`, else P→Q and Q→P.
PairState pair_state(const BondList& b, std::int32_t P, std::int32_t Q, bool one_way) {
  bool found = false, broken = false;
  for (const auto& [x, y] : {std::pair{P, Q}, std::pair{Q, P}}) {
    for (auto k = b.offset[x]; k < b.offset[x + 1]; ++k)
      if (b.neighbor[k] == y) found = true, broken = broken || !b.intact[k];
    if (one_way) break;
  }
  return !found ? PairState::None : (broken ? PairState::Broken : PairState::Intact);
}

/// How many segments of the previous generation properly cross a new segment, and how many of
/// those were broken.
struct Crossings {
  std::size_t all = 0, broken = 0;
};

/// The bonds of the previous generation as planar segments, binned by midpoint.
class OldSegments {
 public:
  OldSegments(const BondList& b, const ParticleStore& p) : b_(b), p_(p) {
    for (std::size_t k = 0; k < b.size(); ++k) {
      cell_ = std::max(cell_, b.length[k]);
      any_broken_ = any_broken_ || !b.intact[k];
    }
    for (std::size_t k = 0; k < b.size() && any_broken_; ++k) bins_[key(mid(k))].push_back(k);
  }
  bool any_broken() const { return any_broken_; }

  /// Old bonds that properly cross a–b, skipping those that touch particle `skip` (−1: none).
  Crossings crossing(const Vec3& a, const Vec3& b, std::int32_t skip) const {
    Crossings c;
    const Vec3 m = 0.5 * (a + b);
    const double reach = 0.5 * cell_ + 0.5 * norm(b - a);
    const auto lo = cell_of({m[0] - reach, m[1] - reach, 0}),
               hi = cell_of({m[0] + reach, m[1] + reach, 0});
    for (auto cx = lo.first; cx <= hi.first; ++cx)
      for (auto cy = lo.second; cy <= hi.second; ++cy) {
        const auto it = bins_.find(pack(cx, cy));
        if (it == bins_.end()) continue;
        for (const auto k : it->second) {
          const auto i = b_.owner[k], j = b_.neighbor[k];
          if (i == skip || j == skip) continue;
          if (!segments_cross_properly(a, b, point(p_.reference_position, i),
                                       point(p_.reference_position, j)))
            continue;
          ++c.all;
          c.broken += b_.intact[k] ? 0 : 1;
        }
      }
    return c;
  }

 private:
  Vec3 mid(std::size_t k) const {
    return 0.5 * (point(p_.reference_position, b_.owner[k]) +
                  point(p_.reference_position, b_.neighbor[k]));
  }
  std::pair<std::int64_t, std::int64_t> cell_of(const Vec3& x) const {
    return {static_cast<std::int64_t>(std::floor(x[0] / cell_)),
            static_cast<std::int64_t>(std::floor(x[1] / cell_))};
  }
  static std::int64_t pack(std::int64_t cx, std::int64_t cy) { return cx * 4294967311LL + cy; }
  std::int64_t key(const Vec3& x) const {
    const auto c = cell_of(x);
    return pack(c.first, c.second);
  }

  const BondList& b_;
  const ParticleStore& p_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> bins_;
  double cell_ = 0.0;
  bool any_broken_ = false;
};

}  // namespace

std::int64_t apply_no_healing(BondList& bonds, const ParticleStore& p,
                              const std::vector<std::int32_t>& previous, std::size_t kept,
                              const BondList& old_bonds, const ParticleStore& old_p) {
  const OldSegments old(old_bonds, old_p);
  if (!old.any_broken()) return 0;
  const bool planar = p.dim() == 2;
  std::int64_t count = 0;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const auto i = bonds.owner[k], j = bonds.neighbor[k];
    const auto P = previous[static_cast<std::size_t>(i)], Q = previous[static_cast<std::size_t>(j)];
    // Two kept particles keep the state of their own bond (a bond and its dual are independent).
    const bool both_kept = static_cast<std::size_t>(i) < kept && static_cast<std::size_t>(j) < kept;
    const PairState state = P == Q ? PairState::None : pair_state(old_bonds, P, Q, both_kept);
    bool cut = state == PairState::Broken;
    if (state == PairState::None && planar) {
      const auto c =
          old.crossing(point(p.reference_position, static_cast<std::size_t>(i)),
                       point(p.reference_position, static_cast<std::size_t>(j)), P == Q ? P : -1);
      cut = P == Q ? 2 * c.broken > c.all : c.broken > 0;
    }
    bonds.intact[k] = cut ? 0 : 1;
    count += cut ? 1 : 0;
  }
  return count;
}

}  // namespace dhpd
