// The instability guard's balance through a refinement event: the energy the state mapping adds or
// takes enters the shadow-energy ledger exactly, and the run goes on stable.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::pulsed_plate;

double shadow(const Energies& e) {
  return e.kinetic + e.strain - e.verlet_correction;
}

TEST(Guard, RefinementMappingEntersTheBalanceExactly) {
  for (const auto mapping : {refine::StateMapping::Copy, refine::StateMapping::Linear}) {
    auto s = pulsed_plate(0.8);
    s.effects.refinement = true;
    Simulation sim(s);
    sim.run_steps(40);
    const auto before = sim.energies();
    std::vector<std::int32_t> parents;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(sim.particles().size()); i += 7)
      parents.push_back(i);
    const auto ev = refine::split(sim, parents, mapping);
    const auto after = sim.energies();
    const double change = after.kinetic + after.strain - before.kinetic - before.strain;
    EXPECT_GT(std::abs(change), 1e-6 * before.kinetic);  // the mapping does change the energy
    EXPECT_NEAR(ev.energy_change, change, 1e-9 * before.kinetic);
    EXPECT_NEAR(ev.shadow_change, shadow(after) - shadow(before), 1e-9 * before.kinetic);
    EXPECT_EQ(sim.energy_budget().mapping, ev.shadow_change);
    EXPECT_NO_THROW(sim.run_steps(100));
    EXPECT_NO_THROW(sim.check_stable(sim.energies()));
  }
}

}  // namespace
}  // namespace dhpd
