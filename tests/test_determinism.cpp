// The same setup gives bit-identical results with 1 and 2 threads (gather form, fixed-order sums).
#include <gtest/gtest.h>
#include <omp.h>

#include "engine/base/parallel.hpp"
#include "refine/refiner.hpp"
#include "tests/support.hpp"

namespace dhpd {
namespace {

SimulationSetup fracturing_plate() {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.materials = {{72e9, 2440, 3.8}};
  s.partial_volume = PartialVolume::Linear;
  using geometry::Box;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.06, 0.024, 0}}, 5e-4, 0},
                                     {Box{{0.02, 0, 0}, {0.04, 0.024, 0}}, 2.5e-4, 0}},
                                    2);
  s.cracks = {{{{0.0, 0.012, 0}, {0.025, 0.012, 0}}}};
  BoundaryCondition top, bottom;
  top.kind = bottom.kind = BoundaryCondition::Kind::Traction;
  top.region = Box{{0, 0.0225, 0}, {0.06, 0.024, 0}};
  bottom.region = Box{{0, 0, 0}, {0.06, 0.0015, 0}};
  top.traction = {0, 40e6, 0};
  bottom.traction = {0, -40e6, 0};
  top.normal_axis = bottom.normal_axis = 1;
  s.boundary_conditions = {top, bottom};
  s.effects.fracture = true;
  return s;
}

struct Result {
  std::vector<double> u, v;
  std::int64_t broken;
  Energies e;
};

/// 200 steps; or 100 with `adaptive`, a damage-triggered refiner checks every 10 steps (the event
/// itself is serial, so only the step loops see the thread count).
Result run_with(int threads, bool adaptive = false) {
  omp_set_num_threads(threads);
  Simulation sim(fracturing_plate());
  EXPECT_GE(static_cast<std::int64_t>(sim.particles().size()), kParallelMinParticles);
  refine::Settings set;
  set.trigger.damage = 0.3;
  set.max_level = 1;
  refine::Refiner refiner(set);
  std::int64_t events = 0;
  const std::int64_t steps = adaptive ? 100 : 200;
  for (std::int64_t k = 1; k <= steps; ++k) {
    sim.step();
    if (adaptive && refiner.due(k)) events += refiner.check(sim).parents > 0 ? 1 : 0;
  }
  if (adaptive) {
    EXPECT_GT(events, 2);
  }
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

TEST(Determinism, AdaptiveRunIsIdenticalWithOneAndTwoThreads) {
  const auto one = run_with(1, true), two = run_with(2, true);
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
