// The single owner of per-particle data, as structure of arrays with a field registry.
// Geometry fields change only at refinement events; state fields change every step.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>
#include <variant>
#include <vector>

#include "geometry/vec.hpp"

namespace dhpd {

/// How a field passes on when refine/ splits a particle: copied, shared out (a volume), set from
/// the split pattern by refine/, or reset.
enum class SplitRule { Copy, Shared, FromPattern, Reset };
enum class FieldGroup { Geometry, State };
/// Whether a field goes into output frames: always, when the scene asks for it, or never.
enum class Export { Always, OnRequest, Never };

using ScalarArray = std::vector<double>;
using VectorArray = std::array<std::vector<double>, 3>;  ///< one array per component
using IndexArray = std::vector<std::int32_t>;
using FlagArray = std::vector<std::uint8_t>;

/// One registered field: its name, group, rule at a split, output, unit and meaning.
struct FieldInfo {
  std::string_view name;
  FieldGroup group;
  SplitRule split;
  Export output;
  std::string_view unit, doc;
  std::variant<ScalarArray*, VectorArray*, IndexArray*, FlagArray*> data;
};

/// Point i of a per-component array (e.g. a reference position) as a Vec3.
inline geometry::Vec3 point_of(const VectorArray& x, std::size_t i) {
  return {x[0][i], x[1][i], x[2][i]};
}

class ParticleStore {
 public:
  explicit ParticleStore(int dim = 3) : dim_(dim) {}

  int dim() const { return dim_; }
  std::size_t size() const { return volume.size(); }
  /// Resize every registered field; new entries are zero.
  void resize(std::size_t n);
  /// Every registered field, in a fixed order: the splitter, the checkpoint and the output
  /// frames (engine/output_fields.hpp) iterate this.
  std::vector<FieldInfo> fields();
  /// Bytes the registered fields hold (capacities: what the allocator gave).
  std::size_t bytes() const;

  // Geometry (reference configuration; rewritten only by refinement).
  VectorArray reference_position;
  ScalarArray volume, spacing, horizon, density;
  ScalarArray radius;  ///< equal-measure radius r_i of the particle (exact partial volumes)
  IndexArray material, id;
  IndexArray level;      ///< refinement level: 0 for particles of the scene, +1 per split
  IndexArray parent_id;  ///< id of the particle this one was split from, −1 for scene particles
  FlagArray no_fail;
  // State (advanced every step).
  VectorArray position;  ///< current position y = X + u
  VectorArray displacement, velocity;
  VectorArray force_density;  ///< internal + external force per unit volume (N/m³)
  ScalarArray damage;

 private:
  int dim_;
};

/// The particles `indices` of `p` (in that order) as a store of their own, every field copied.
ParticleStore gather(ParticleStore& p, const std::vector<std::int32_t>& indices);

/// values[k] = values[order[k]] for the slots k of `moved` (order[k] = k elsewhere): what a
/// renumbering that moves a few slots does to one per-slot array.
template <class V>
void move_slots(std::vector<V>& values, const std::vector<std::int32_t>& order,
                const std::vector<std::int32_t>& moved) {
  std::vector<V> from(moved.size());
  for (std::size_t t = 0; t < moved.size(); ++t)
    from[t] = values[static_cast<std::size_t>(order[static_cast<std::size_t>(moved[t])])];
  for (std::size_t t = 0; t < moved.size(); ++t)
    values[static_cast<std::size_t>(moved[t])] = from[t];
}

/// Renumbers `p` in place by `order` (order[k]: the particle that goes to slot k) where it moves
/// only the slots `moved` (ascending; order[k] = k elsewhere): every field, those slots alone.
void permute_slots(ParticleStore& p, const std::vector<std::int32_t>& order,
                   const std::vector<std::int32_t>& moved);

}  // namespace dhpd
