// A simulation with a damage-triggered refiner, stepped like the run loop does (the checkpoint and
// guard-copy tests of refine/ use it on both sides of a snapshot).
#pragma once
#include <cstdint>
#include <optional>

#include "engine/simulation.hpp"
#include "refine/refiner.hpp"

namespace dhpd::test {

struct AdaptiveRun {
  explicit AdaptiveRun(const SimulationSetup& setup) : sim(setup) {
    refine::Settings set;
    set.trigger.damage = 0.02;
    set.max_level = 1;
    set.check_every = 5;
    refiner.emplace(set);
  }
  void advance(std::int64_t steps) {
    for (std::int64_t k = 0; k < steps; ++k) {
      sim.step();
      if (!refiner->due(sim.steps_done(), sim)) continue;  // as the runner asks
      const auto ev = refiner->check(sim);
      events += ev.parents > 0 ? 1 : 0;
      resorts += ev.resorted ? 1 : 0;
    }
  }
  Simulation sim;
  std::optional<refine::Refiner> refiner;
  int events = 0, resorts = 0;
};

}  // namespace dhpd::test
