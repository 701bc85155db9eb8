// The per-particle fields a frame can hold, each with its unit and a one-line description: the
// particle store's exported fields (its registry) and the derived quantities the engine computes
// on demand. The VTK writer, the scene's `output.fields` and `dhpd fields` all read this list.
#pragma once
#include <cstdint>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "engine/simulation.hpp"

namespace dhpd {

struct OutputField {
  std::string_view name, unit, doc;
  bool always;  ///< written in every frame; the others on request (`output.fields`)
};

/// Every field, the store's exported ones first in registry order, then the derived ones.
std::vector<OutputField> output_fields();

/// A field's values for the current state: `components` numbers per particle, interleaved.
struct FieldValues {
  int components = 1;
  std::variant<std::vector<double>, std::vector<std::int32_t>> values;
};

/// The values of field `name`; throws EngineError for a name not in output_fields().
FieldValues output_values(Simulation& sim, std::string_view name);

/// The particle-store field exported as `name` (nullopt for a derived field or another name).
std::optional<FieldInfo> exported_store_field(ParticleStore& p, std::string_view name);
/// output_values of store field `f` laid out for `n` particles, not yet copied: zeros, or, in
/// `reuse`'s array when its type fits, whatever that array held (copy_values overwrites it).
FieldValues blank_values(const FieldInfo& f, std::size_t n,
                         std::variant<std::vector<double>, std::vector<std::int32_t>> reuse = {});
/// Copies particles [begin, end) of store field `f` to `out`, the data of its blank_values:
/// threads may copy disjoint ranges at once.
void copy_values(const FieldInfo& f, std::variant<double*, std::int32_t*> out, std::int64_t begin,
                 std::int64_t end);

}  // namespace dhpd
