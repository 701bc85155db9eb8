// Children of a refinement event: layout, mapped state, field registry (docs/theory.md §13.3; IJNME
// 2016 §5.3).
#include "refine/split_plan.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include "engine/base/errors.hpp"
#include "geometry/lattice.hpp"

namespace dhpd::refine {

using geometry::Vec3;

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

bool ChildFilter::allows(const Vec3& child) const {
  return !body || body->contains(child, dim);
}

namespace {
bool crosses_a_crack(const std::vector<geometry::Crack>& cracks, const Vec3& a, const Vec3& b,
                     int dim) {
  for (const auto& c : cracks)
    if (geometry::crosses(c, a, b, dim)) return true;
  return false;
}
}  // namespace

std::vector<std::int32_t> donors_across_cracks(const SplitPlan& plan, const ParticleStore& p,
                                               const std::vector<geometry::Crack>& cracks,
                                               const SpatialGrid& grid) {
  std::vector<std::int32_t> donor(plan.child_position.size(), -1);
  if (cracks.empty()) return donor;
  const int dim = p.dim();
  std::vector<std::int32_t> near;
  for (std::size_t c = 0; c < donor.size(); ++c) {
    const auto q = static_cast<std::size_t>(plan.parents[plan.child_parent[c]]);
    const Vec3& xc = plan.child_position[c];
    if (!crosses_a_crack(cracks, point_of(p.reference_position, q), xc, dim)) continue;
    grid.within(xc, p.horizon[q], near, static_cast<std::int32_t>(q));
    double best = HUGE_VAL;
    for (const auto j : near) {  // ascending: the first of equally near ones wins
      const Vec3 xj = point_of(p.reference_position, static_cast<std::size_t>(j));
      double d2 = 0.0;
      for (int a = 0; a < dim; ++a) d2 += (xj[a] - xc[a]) * (xj[a] - xc[a]);
      if (d2 < best && !crosses_a_crack(cracks, xc, xj, dim)) {
        best = d2;
        donor[c] = j;
      }
    }
  }
  return donor;
}

SplitPlan plan_split(const ParticleStore& p, const std::vector<std::int32_t>& parents,
                     const ChildFilter& filter) {
  SplitPlan plan;
  plan.old_size = p.size();
  std::vector<std::int32_t> sorted(parents);
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    if (sorted[k] < 0 || static_cast<std::size_t>(sorted[k]) >= p.size())
      throw EngineError("split: parent index out of range");
    if (k > 0 && sorted[k] == sorted[k - 1]) throw EngineError("split: a parent is listed twice");
  }
  std::vector<std::size_t> appended;  // children that get a new slot
  for (const auto q : parents) {
    const auto xq = point_of(p.reference_position, static_cast<std::size_t>(q));
    const std::size_t first = plan.child_position.size();
    for (const auto& off : child_offsets(p.dim(), p.spacing[static_cast<std::size_t>(q)]))
      if (filter.allows(xq + off)) plan.child_position.push_back(xq + off);
    const std::size_t made = plan.child_position.size() - first;
    if (made == 0) continue;
    plan.dropped += (std::size_t{1} << p.dim()) - made;
    for (std::size_t c = first; c < first + made; ++c) {
      plan.child_parent.push_back(static_cast<std::int32_t>(plan.parents.size()));
      plan.child_slot.push_back(c == first ? q : -1);
      if (c != first) appended.push_back(c);
    }
    plan.parents.push_back(q);
    plan.child_count.push_back(static_cast<std::int32_t>(made));
  }
  std::vector<Vec3> where(appended.size());
  for (std::size_t k = 0; k < appended.size(); ++k) where[k] = plan.child_position[appended[k]];
  const auto order = geometry::morton_order(where, p.dim());
  for (std::size_t k = 0; k < order.size(); ++k)
    plan.child_slot[appended[static_cast<std::size_t>(order[k])]] =
        static_cast<std::int32_t>(plan.old_size + k);
  plan.new_size = plan.old_size + appended.size();
  return plan;
}

namespace {

/// Copies (Copy), divides (Shared) or resets (Reset) every registered field from the
/// parent; FromPattern fields are copied here and overwritten by `set_pattern_fields`.
void map_fields(ParticleStore& p, const SplitPlan& plan, ParticleStore& parents) {
  auto src = parents.fields();
  auto dst = p.fields();
  for (std::size_t f = 0; f < dst.size(); ++f) {
    const SplitRule rule = dst[f].split;
    std::visit(
        [&](auto* to) {
          using T = std::remove_pointer_t<decltype(to)>;
          const T* from = std::get<T*>(src[f].data);
          auto one = [&](auto& out, const auto& in) {
            using V = typename std::remove_reference_t<decltype(out)>::value_type;
            for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
              const auto k = static_cast<std::size_t>(plan.child_parent[c]);
              V v = rule == SplitRule::Reset ? V{} : in[k];
              if constexpr (std::is_floating_point_v<V>)
                if (rule == SplitRule::Shared) v /= plan.child_count[k];
              out[static_cast<std::size_t>(plan.child_slot[c])] = v;
            }
          };
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (int a = 0; a < 3; ++a) one((*to)[a], (*from)[a]);
          } else {
            one(*to, *from);
          }
        },
        dst[f].data);
  }
}

void set_pattern_fields(ParticleStore& p, const SplitPlan& plan, const ParticleStore& parents,
                        const ChildState& state, const Section& section, std::int32_t next_id) {
  for (std::size_t c = 0; c < plan.child_slot.size(); ++c) {
    const auto s = static_cast<std::size_t>(plan.child_slot[c]);
    const auto k = static_cast<std::size_t>(plan.child_parent[c]);
    for (int a = 0; a < 3; ++a) {
      p.reference_position[a][s] = plan.child_position[c][a];
      p.displacement[a][s] = state.displacement[c][a];
      p.velocity[a][s] = state.velocity[c][a];
      p.position[a][s] = p.reference_position[a][s] + p.displacement[a][s];
    }
    p.spacing[s] = 0.5 * parents.spacing[k];
    p.horizon[s] = 0.5 * parents.horizon[k];
    p.radius[s] = section.equal_measure_radius(p.volume[s]);
    p.id[s] = next_id + static_cast<std::int32_t>(c);
    p.level[s] = parents.level[k] + 1;
    p.parent_id[s] = parents.id[k];
  }
}

}  // namespace

void write_children(ParticleStore& p, const SplitPlan& plan, ParticleStore& parents,
                    const ChildState& state, const Section& section, std::int32_t next_id) {
  static constexpr std::string_view handled[] = {
      "reference_position", "spacing", "horizon", "radius", "id", "level", "parent_id", "position"};
  for (const auto& f : p.fields())
    if (f.split == SplitRule::FromPattern &&
        std::find(std::begin(handled), std::end(handled), f.name) == std::end(handled))
      throw EngineError("split: no pattern rule for field '" + std::string(f.name) + "'");
  p.resize(plan.new_size);
  map_fields(p, plan, parents);
  set_pattern_fields(p, plan, parents, state, section, next_id);
}

}  // namespace dhpd::refine
