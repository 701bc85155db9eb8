// Refinement with the ordinary state-based family (docs/theory.md §20.6): momentum and damage
// through an adaptive run, children with their own m and θ, a restart bit for bit after events,
// the same bits with 1 and 2 threads, and the level-interface factors solved again per event.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/physics/ordinary_state.hpp"
#include "refine/refiner.hpp"
#include "tests/support/adaptive_run.hpp"
#include "tests/support/checkpoint.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

/// The setup as the ordinary state-based family with ν = 0.3.
SimulationSetup state_based(SimulationSetup s) {
  s.family = ModelFamily::OrdinaryState;
  for (auto& m : s.materials) m.nu = 0.3;
  return s;
}

class StateRefinement : public ::testing::TestWithParam<PartialVolume> {};

// The pre-cracked plate under equal and opposite tractions, with each partial-volume rule: events
// while the crack runs keep the momentum at round-off and the damage current; the children get
// their own m (the sum over their own horizons) and the interface factors are solved for each
// event's rows.
TEST_P(StateRefinement, MomentumDamageAndOwnWeightedVolumesThroughAnAdaptiveRun) {
  auto setup = state_based(test::pulled_cracked_plate(1e-3));
  setup.partial_volume = GetParam();
  Simulation sim(setup);
  refine::Settings set;
  set.trigger.damage = 0.02;
  set.check_every = 5;
  refine::Refiner refiner(set);
  int events = 0;
  std::size_t corrected = 0;
  double worst = 0.0;
  for (int k = 1; k <= 200; ++k) {
    sim.step();
    if (refiner.due(k)) {
      const auto ev = refiner.check(sim);
      events += ev.parents > 0 ? 1 : 0;
      corrected += ev.interfaces.bonds;
    }
    if (k % 20 != 0) continue;
    auto full = sim.particles();
    compute_damage(sim.bonds(), full, sim.setup().partial_volume);
    ASSERT_EQ(full.damage, sim.particles().damage) << "step " << k;
    worst = std::max(worst, test::relative_momentum(sim));
  }
  // m of every particle, children included, is its own horizon's sum (20.1) over the rows.
  const auto* model = sim.ordinary_state();
  ASSERT_NE(model, nullptr);
  const OrdinaryState fresh(sim.bonds(), sim.particles(),
                            {sim.setup().section, sim.setup().model, sim.setup().partial_volume,
                             sim.setup().influence, &sim.setup().materials, true});
  EXPECT_EQ(model->weighted_volume(), fresh.weighted_volume());
  // The event's model, its solved factors put on the weights in place, is the rows' model.
  EXPECT_EQ(model->own_deviatoric_weight(), fresh.own_deviatoric_weight());
  EXPECT_EQ(model->own_dilatation_weight(), fresh.own_dilatation_weight());
  EXPECT_EQ(model->dual_deviatoric_weight(), fresh.dual_deviatoric_weight());
  EXPECT_EQ(model->dual_dilatation_weight(), fresh.dual_dilatation_weight());
  std::printf(
      "state-based adaptive run: %d events, %zu particles, %zu bonds corrected, worst "
      "|P|/sum m|v| %.2e\n",
      events, sim.particles().size(), corrected, worst);
  EXPECT_GE(events, 5);
  EXPECT_GT(corrected, 0u);
  EXPECT_LT(worst, 1e-13);
}

INSTANTIATE_TEST_SUITE_P(PartialVolumes, StateRefinement,
                         ::testing::Values(PartialVolume::None, PartialVolume::Linear,
                                           PartialVolume::Exact));

using Stepper = test::AdaptiveRun;

TEST(StateRefinementRuns, RestartsBitForBitWithEventsOnBothSides) {
  auto setup = state_based(test::pulled_cracked_plate(1e-3));
  setup.resort_fraction = 0.02;
  const auto ev = test::expect_restart_exact<Stepper>(setup, 100, 100);
  EXPECT_GE(ev.before, 2) << "events before the checkpoint";
  EXPECT_GE(ev.total - ev.before, 2) << "events after the checkpoint";
}

/// 60 steps of the pulled, pre-cracked plate at 0.45 mm (4,884 particles: the passes run on
/// every thread), state-based, with `threads` threads.
std::vector<double> run_with(int threads, std::int64_t& events) {
  omp_set_num_threads(threads);
  Simulation sim(state_based(test::pulled_cracked_plate(4.5e-4)));
  EXPECT_GE(static_cast<std::int64_t>(sim.particles().size()), kParallelMinParticles);
  refine::Settings set;
  set.trigger.damage = 0.02;
  set.check_every = 5;
  refine::Refiner refiner(set);
  events = 0;
  for (std::int64_t k = 1; k <= 60; ++k) {
    sim.step();
    if (refiner.due(k)) events += refiner.check(sim).parents > 0 ? 1 : 0;
  }
  std::vector<double> out;
  const auto& p = sim.particles();
  for (int a = 0; a < 2; ++a) {
    out.insert(out.end(), p.displacement[a].begin(), p.displacement[a].end());
    out.insert(out.end(), p.velocity[a].begin(), p.velocity[a].end());
  }
  return out;
}

TEST(StateRefinementRuns, AdaptiveRunIsIdenticalWithOneAndTwoThreads) {
  std::int64_t events_one = 0, events_two = 0;
  const auto one = run_with(1, events_one), two = run_with(2, events_two);
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_GE(events_one, 1);
  EXPECT_EQ(events_one, events_two);
  EXPECT_EQ(one, two);
}

}  // namespace
}  // namespace dhpd
