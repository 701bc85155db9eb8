// When a loop over particles is worth a thread team: below this many particles the fork/join
// and barrier cost more than the work (and on a loaded machine a waiting team can stall for
// milliseconds), so small problems run on one thread. Results do not depend on it: every
// parallel loop is a gather with a fixed order per particle.
#pragma once
#include <cstdint>
#include <type_traits>

namespace dhpd {
inline constexpr std::int64_t kParallelMinParticles = 4096;

/// Calls f(std::integral_constant<int, D>{}) with D = dim (1, 2, else 3): the one place a run's
/// dimension picks a kernel's instantiation, once per call and never per bond.
template <class F>
decltype(auto) with_dim(int dim, F&& f) {
  if (dim == 1) return f(std::integral_constant<int, 1>{});
  if (dim == 2) return f(std::integral_constant<int, 2>{});
  return f(std::integral_constant<int, 3>{});
}
}  // namespace dhpd
