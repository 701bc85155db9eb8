// An adaptive run gives bit-identical results with 1 and 2 threads: the event itself is serial,
// so only the step loops see the thread count (without events: tests/engine/test_determinism.cpp).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <cstdio>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/simulation.hpp"
#include "refine/refiner.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

struct Result {
  std::vector<double> u, v;
  std::int64_t broken;
  Energies e;
};

/// 100 steps of the two-part fracturing plate with `threads` threads; a damage-triggered refiner
/// checks every 10 steps.
Result run_with(int threads) {
  omp_set_num_threads(threads);
  Simulation sim(test::fracturing_plate());
  EXPECT_GE(static_cast<std::int64_t>(sim.particles().size()), kParallelMinParticles);
  refine::Settings set;
  set.trigger.damage = 0.3;
  set.max_level = 1;
  refine::Refiner refiner(set);
  std::int64_t events = 0;
  for (std::int64_t k = 1; k <= 100; ++k) {
    sim.step();
    if (refiner.due(k)) events += refiner.check(sim).parents > 0 ? 1 : 0;
  }
  EXPECT_GT(events, 2);
  Result r;
  const auto& p = sim.particles();
  for (int a = 0; a < 2; ++a) {
    r.u.insert(r.u.end(), p.displacement[a].begin(), p.displacement[a].end());
    r.v.insert(r.v.end(), p.velocity[a].begin(), p.velocity[a].end());
  }
  r.broken = sim.broken_bonds();
  r.e = sim.energies();
  return r;
}

TEST(Determinism, AdaptiveRunIsIdenticalWithOneAndTwoThreads) {
  const auto one = run_with(1), two = run_with(2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("adaptive: %zu particles, %lld broken bonds after 100 steps\n", one.u.size() / 2,
              static_cast<long long>(one.broken));
  EXPECT_EQ(one.broken, two.broken);
  EXPECT_EQ(one.u, two.u);
  EXPECT_EQ(one.v, two.v);
  EXPECT_EQ(one.e.strain, two.e.strain);
}

}  // namespace
}  // namespace dhpd
