// When a loop over particles is worth a thread team: below this many particles the fork/join
// and barrier cost more than the work (and on a loaded machine a waiting team can stall for
// milliseconds), so small problems run on one thread. Results do not depend on it: every
// parallel loop is a gather with a fixed order per particle.
#pragma once
#include <cstdint>
#include <functional>
#include <type_traits>

namespace dhpd {
inline constexpr std::int64_t kParallelMinParticles = 4096;

/// Work a caller hands to a parallel pass over particles: one thread of the team runs it once
/// while the others start the pass, then joins the pass (its rows are handed out dynamically), so
/// where the team has every core it costs about its own time divided by the team's size instead
/// of stealing a core from the team. It must not touch anything the pass reads or writes, and must
/// not throw (it keeps its own errors). The pass's results do not depend on it.
using SideTask = std::function<void()>;

/// Calls f(std::integral_constant<int, D>{}) with D = dim (1, 2, else 3): the one place a run's
/// dimension picks a kernel's instantiation, once per call and never per bond.
template <class F>
decltype(auto) with_dim(int dim, F&& f) {
  if (dim == 1) return f(std::integral_constant<int, 1>{});
  if (dim == 2) return f(std::integral_constant<int, 2>{});
  return f(std::integral_constant<int, 3>{});
}
}  // namespace dhpd
