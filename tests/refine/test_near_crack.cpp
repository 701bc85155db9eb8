// The `near_crack` limit of the stretch trigger (docs/theory.md §13.1): a particle counts as near
// a crack when it lies within near_precrack · δ_i of a pre-crack's front or within near_crack · δ_j
// of a particle j damaged to kFrontDamage, δ_j being that damaged particle's own horizon.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/simulation.hpp"
#include "geometry/crack.hpp"
#include "refine/refiner.hpp"
#include "refine/triggers.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::Box;

/// A 60 × 20 mm plate with a 10 mm pre-crack from its left edge at mid-height, the part right
/// of x = 20 mm above mid-height lifted by 2 % of a spacing, a refined patch 20 × 6 mm around
/// (40, 10) mm and one short step: the bonds across the lift break, in coarse particles and in
/// children.
Simulation cracked_refined_plate() {
  auto s = test::plate(1e-3, 0.06, 0.02);
  s.effects.fracture = true;
  s.cracks = {{{{0, 0.01, 0}, {0.01, 0.01, 0}}}};
  InitialCondition lift;
  lift.region = Box{{0.02, 0.01, 0}, {0.06, 0.02, 0}};
  lift.displacement = geometry::Vec3{0, 2e-5, 0};
  s.initial_conditions = {lift};
  s.fixed_dt = 1e-9;
  Simulation sim(s);
  refine::Settings set;
  set.zones = {Box{{0.03, 0.007, 0}, {0.05, 0.013, 0}}};
  refine::Refiner(set).refine_zones(sim);
  sim.step();
  return sim;
}

double distance(const ParticleStore& p, std::size_t i, std::size_t j) {
  double d2 = 0.0;
  for (int a = 0; a < p.dim(); ++a)
    d2 += std::pow(p.reference_position[a][i] - p.reference_position[a][j], 2);
  return std::sqrt(d2);
}

/// The rule written out pair by pair: `own_horizon` counts a damaged particle's reach in its own
/// horizon (the rule), otherwise in the horizon of the particle asked (the rule before).
std::vector<std::uint8_t> brute_force(const Simulation& sim, refine::CrackReach reach,
                                      bool own_horizon) {
  const auto& p = sim.particles();
  std::vector<geometry::CrackFront> fronts;
  for (const auto& c : sim.setup().cracks) {
    const auto f = geometry::crack_fronts(c, 2, 2.5e-4, [](const geometry::Vec3&) { return true; });
    fronts.insert(fronts.end(), f.begin(), f.end());
  }
  std::vector<std::uint8_t> out(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto x = point_of(p.reference_position, i);
    for (const auto& f : fronts)
      if (geometry::distance_to(f, x) <= reach.precrack * p.horizon[i]) out[i] = 1;
    for (std::size_t j = 0; j < p.size() && !out[i]; ++j)
      if (p.damage[j] >= refine::kFrontDamage &&  // j = i: a damaged particle is a front itself
          distance(p, i, j) <= reach.running * (own_horizon ? p.horizon[j] : p.horizon[i]))
        out[i] = 1;
  }
  return out;
}

TEST(NearCrack, ReachesARunningCrackInItsOwnHorizonAndAPreCrackInTheAskersOne) {
  const Simulation sim = cracked_refined_plate();
  const auto& p = sim.particles();
  std::size_t damaged_children = 0, damaged_coarse = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.damage[i] >= refine::kFrontDamage) (p.level[i] > 0 ? damaged_children : damaged_coarse)++;
  ASSERT_GT(damaged_children, 0u);
  ASSERT_GT(damaged_coarse, 0u);
  const std::vector<std::uint8_t> all(p.size(), 1);
  for (const refine::CrackReach reach : {refine::CrackReach{1.0, 2.0}, refine::CrackReach{1.5, 1.5},
                                         refine::CrackReach{0.75, 3.0}}) {
    const auto got = refine::near_a_crack(sim, reach, all);
    const auto expected = brute_force(sim, reach, true);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (got[i] != expected[i] && differ++ < 5)
        ADD_FAILURE() << "particle " << i << " at " << p.reference_position[0][i] << ", "
                      << p.reference_position[1][i] << " level " << p.level[i] << ": near_a_crack "
                      << int(got[i]) << ", pair by pair " << int(expected[i]) << " (reach "
                      << reach.running << " / " << reach.precrack << ")";
    EXPECT_EQ(differ, 0u);
    // The rule differs from one counted in the asker's horizon: some coarse particles next to
    // the refined crack lie beyond what δ_j = δ/2 reaches (with running ≥ 1: the patch is
    // 3 mm = δ high on each side of the crack).
    if (reach.running < 1.0) continue;
    const auto askers = brute_force(sim, reach, false);
    std::size_t coarse_left_out = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      coarse_left_out += askers[i] && !got[i] && p.level[i] == 0 ? 1 : 0;
    EXPECT_GT(coarse_left_out, 0u) << reach.running << " / " << reach.precrack;
  }
  // Only the particles asked can be near.
  std::vector<std::uint8_t> none(p.size(), 0);
  const auto got = refine::near_a_crack(sim, {1.0, 2.0}, none);
  EXPECT_EQ(std::count(got.begin(), got.end(), 1), 0);
}

TEST(NearCrack, APreCrackReachOfItsOwnWidensOnlyAroundThePreCrack) {
  const Simulation sim = cracked_refined_plate();
  const auto& p = sim.particles();
  const std::vector<std::uint8_t> all(p.size(), 1);
  const auto narrow = refine::near_a_crack(sim, {1.0, 1.0}, all);
  const auto wide = refine::near_a_crack(sim, {1.0, 2.0}, all);
  std::size_t added = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_GE(wide[i], narrow[i]);
    if (wide[i] && !narrow[i]) {
      ++added;  // every particle added lies within 2 δ_i of a pre-crack front: the tip (10, 10)
      // mm, or the mouth (0, 10) mm, a front too in a setup without a body shape
      const double y = p.reference_position[1][i] - 0.01;
      const double d = std::min(std::hypot(p.reference_position[0][i] - 0.01, y),
                                std::hypot(p.reference_position[0][i], y));
      EXPECT_LE(d, 2.0 * p.horizon[i] + 1e-12);
      EXPECT_GT(d, p.horizon[i] - 1e-12);
    }
  }
  EXPECT_GT(added, 0u);
}

}  // namespace
}  // namespace dhpd
