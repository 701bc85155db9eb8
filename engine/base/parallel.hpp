// When a loop over particles is worth a thread team: below this many particles the fork/join
// and barrier cost more than the work (and on a loaded machine a waiting team can stall for
// milliseconds), so small problems run on one thread. Results do not depend on it: every
// parallel loop is a gather with a fixed order per particle.
#pragma once
#include <cstdint>

namespace dhpd {
inline constexpr std::int64_t kParallelMinParticles = 4096;
}  // namespace dhpd
