// When a loop over particles is worth a thread team: below this many particles the fork/join
// and barrier cost more than the work (and on a loaded machine a waiting team can stall for
// milliseconds), so small problems run on one thread. Results do not depend on it: every
// parallel loop is a gather with a fixed order per particle.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <type_traits>
#include <utility>
#include <vector>

namespace dhpd {
inline constexpr std::int64_t kParallelMinParticles = 4096;

/// Work a caller hands to a parallel pass over particles: one thread of the team runs it once
/// while the others start the pass, then joins the pass (its rows are handed out dynamically), so
/// where the team has every core it costs about its own time divided by the team's size instead
/// of stealing a core from the team. It must not touch anything the pass reads or writes, and must
/// not throw (it keeps its own errors). The pass's results do not depend on it.
using SideTask = std::function<void()>;

/// Work a caller hands to a parallel pass over particles for a range [begin, end) of them: each
/// thread of the team calls it once, for the range it then works on (the ranges are disjoint and
/// cover every particle), so the work is shared by the team inside the pass's own fork and join.
using RangeTask = std::function<void(std::int64_t begin, std::int64_t end)>;

/// Work a caller does between two phases of a step, on the whole state and outside any parallel
/// pass (e.g. a refinement event between two relaxations of a static load step): returns whether
/// it edited the discretisation.
using EditTask = std::function<bool()>;

/// The part [begin, end) of n items that thread `thread` of a team of `team` takes: contiguous
/// ranges in thread order, the first n % team of them one item longer.
inline std::pair<std::int64_t, std::int64_t> team_range(std::int64_t n, int thread, int team) {
  const std::int64_t base = n / team, extra = n % team;
  const std::int64_t begin = thread * base + std::min<std::int64_t>(thread, extra);
  return {begin, begin + base + (thread < extra ? 1 : 0)};
}

/// f(i) for every particle i < count, in parallel from kParallelMinParticles on (static
/// schedule); each call writes only its own particle's results.
template <class F>
void for_each_particle(std::size_t count, F&& f) {
  const auto n = static_cast<std::int64_t>(count);
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) f(static_cast<std::size_t>(i));
}

/// f(i) for the particles `subset` lists, or for all `count` when it is null, in parallel from
/// kParallelMinParticles on.
template <class F>
void for_each_particle(std::size_t count, const std::vector<std::int32_t>* subset, F&& f) {
  if (!subset) return for_each_particle(count, f);
  const auto n = static_cast<std::int64_t>(subset->size());
  const std::int32_t* slots = subset->data();
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t k = 0; k < n; ++k) f(static_cast<std::size_t>(slots[k]));
}

/// Σ over fixed blocks of kSumBlock particles of f(i, sums), in parallel from
/// kParallelMinParticles on, the blocks' sums added in order (Sums::operator+=): the same bits for
/// any thread count.
inline constexpr std::int64_t kSumBlock = 1024;
template <class Sums, class F>
Sums blocked_sum(std::size_t count, F&& f) {
  const auto n = static_cast<std::int64_t>(count);
  const std::int64_t blocks = (n + kSumBlock - 1) / kSumBlock;
  std::vector<Sums> part(static_cast<std::size_t>(blocks));
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t b = 0; b < blocks; ++b) {
    Sums s;
    for (std::int64_t i = b * kSumBlock; i < std::min(n, (b + 1) * kSumBlock); ++i)
      f(static_cast<std::size_t>(i), s);
    part[static_cast<std::size_t>(b)] = s;
  }
  Sums total;
  for (const auto& s : part) total += s;
  return total;
}

/// Calls f(std::integral_constant<int, D>{}) with D = dim (1, 2, else 3): the one place a run's
/// dimension picks a kernel's instantiation, once per call and never per bond.
template <class F>
decltype(auto) with_dim(int dim, F&& f) {
  if (dim == 1) return f(std::integral_constant<int, 1>{});
  if (dim == 2) return f(std::integral_constant<int, 2>{});
  return f(std::integral_constant<int, 3>{});
}
}  // namespace dhpd
