// The same setup gives bit-identical results with 1 and 2 threads (gather form, fixed-order sums).
// (An adaptive run with refinement events: tests/refine/test_determinism_events.cpp.)
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <cstdio>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/simulation.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

struct Result {
  std::vector<double> u, v;
  std::int64_t broken;
  Energies e;
};

/// 200 steps of the two-part fracturing plate with `threads` threads.
Result run_with(int threads) {
  omp_set_num_threads(threads);
  Simulation sim(test::fracturing_plate());
  EXPECT_GE(static_cast<std::int64_t>(sim.particles().size()), kParallelMinParticles);
  for (std::int64_t k = 1; k <= 200; ++k) sim.step();
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

TEST(Determinism, OneAndTwoThreadsGiveIdenticalNumbers) {
  const auto one = run_with(1), two = run_with(2);
  omp_set_num_threads(omp_get_num_procs());
  std::printf("broken bonds after 200 steps: %lld (1 thread), %lld (2 threads)\n",
              static_cast<long long>(one.broken), static_cast<long long>(two.broken));
  EXPECT_GT(one.broken, 0);  // the test exercises fracture, not just elasticity
  EXPECT_EQ(one.broken, two.broken);
  EXPECT_EQ(one.u, two.u);
  EXPECT_EQ(one.v, two.v);
  EXPECT_EQ(one.e.kinetic, two.e.kinetic);
  EXPECT_EQ(one.e.strain, two.e.strain);
  EXPECT_EQ(one.e.external_work, two.e.external_work);
}

}  // namespace
}  // namespace dhpd
