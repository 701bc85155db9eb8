// Helpers of the refinement tests. They read only the engine's particle store (ids, parent ids),
// so they need no library above the engine.
#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd::test {

/// The children of an event and their parents' slots before it, found by ids: a child is a
/// particle of `after` whose parent_id names a particle of `before` (the store just before the
/// event). Children in ascending slot order.
struct Family {
  std::vector<std::int32_t> child_slot, parent_slot;
};
inline Family family_of_event(const ParticleStore& before, const ParticleStore& after) {
  std::unordered_map<std::int32_t, std::int32_t> slot_of_id;
  for (std::size_t i = 0; i < before.size(); ++i)
    slot_of_id[before.id[i]] = static_cast<std::int32_t>(i);
  Family f;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const auto it = slot_of_id.find(after.parent_id[i]);
    if (after.parent_id[i] < 0 || it == slot_of_id.end()) continue;
    f.child_slot.push_back(static_cast<std::int32_t>(i));
    f.parent_slot.push_back(it->second);
  }
  return f;
}

}  // namespace dhpd::test
