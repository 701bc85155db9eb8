// No healing (docs/theory.md §13.5): a plate separated by broken bonds stays separated when the
// particles around the crack are refined, no intact bond joins a previously broken pair after a
// run, and the segment rule behind it.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <set>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"
#include "geometry/crack.hpp"
#include "refine/event.hpp"
#include "refine/no_healing.hpp"
#include "refine/refiner.hpp"
#include "refine/split_plan.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::all_particles;
using test::Box;
using test::plate;

geometry::Vec3 ref(const ParticleStore& p, std::size_t i) {
  return {p.reference_position[0][i], p.reference_position[1][i], 0};
}

/// Number of intact bonds whose reference segment crosses `line`.
std::size_t intact_crossing(const Simulation& sim, const geometry::Crack& line) {
  const auto& b = sim.bonds();
  std::size_t n = 0;
  for (std::size_t i = 0; i < b.particles(); ++i)
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      if (b.own_intact(k) &&
          geometry::crosses(line, ref(sim.particles(), i), ref(sim.particles(), j), 2))
        ++n;
    });
  return n;
}

TEST(Refinement, SeparatedPlateStaysSeparatedAfterRefiningAroundTheCrack) {
  // Pre-crack on the left half; the upper half is displaced rigidly by 0.1 mm so that the first
  // step breaks every other bond across y = 10 mm: a crack made of broken bonds, not geometry.
  auto s = plate(0.5e-3, 0.05, 0.02);
  s.effects.fracture = true;
  s.cracks = {{{{0, 0.01, 0}, {0.025, 0.01, 0}}}};
  InitialCondition lift;
  lift.region = Box{{0, 0.01, 0}, {0.05, 0.02, 0}};
  lift.displacement = geometry::Vec3{0, 1e-4, 0};
  s.initial_conditions = {lift};
  s.fixed_dt = 1e-9;  // a short first step: the lifted state breaks the bonds, not its rebound
  Simulation sim(s);
  sim.step();
  const geometry::Crack line{{{0, 0.01, 0}, {0.05, 0.01, 0}}};
  ASSERT_GT(sim.broken_bonds(), 0);
  ASSERT_EQ(intact_crossing(sim, line), 0u);
  std::vector<std::int32_t> parents;
  for (const auto i : all_particles(sim))
    if (std::abs(sim.particles().reference_position[1][i] - 0.01) < 3e-3) parents.push_back(i);
  const auto ev = refine::split(sim, parents);
  std::printf("separated plate: %zu parents, %lld new bonds start broken\n", ev.parents,
              static_cast<long long>(ev.started_broken));
  EXPECT_GT(ev.started_broken, 0);
  EXPECT_EQ(intact_crossing(sim, line), 0u);
}

TEST(Refinement, NoIntactBondBetweenPreviouslyBrokenPairsAfterARun) {
  const auto s = test::pulled_cracked_plate(0.5e-3);
  Simulation sim(s);
  for (int k = 0; k < 400 && sim.broken_bonds() < 300; ++k) sim.run_steps(10);
  ASSERT_GE(sim.broken_bonds(), 300);
  const auto old_p = sim.particles();
  const auto old_b = sim.bonds();
  std::set<std::pair<std::int32_t, std::int32_t>> broken;  // by id, both orders
  for (std::size_t x = 0; x < old_b.particles(); ++x)
    for_each_own_bond(old_b, x, [&](std::int64_t k, std::size_t y) {
      if (old_b.own_intact(k)) return;
      const auto i = old_p.id[x], j = old_p.id[y];
      broken.insert({i, j}), broken.insert({j, i});
    });
  std::vector<std::uint8_t> marked(old_p.size(), 0);
  for (std::size_t i = 0; i < marked.size(); ++i) marked[i] = sim.particles().damage[i] > 0.0;
  refine::add_buffer(sim.particles(), 1.0, marked);
  refine::split(sim, refine::graded_parents(sim, marked, 1));
  // The previous identity of a particle: its own id when kept, its parent's id when a child.
  const auto& p = sim.particles();
  auto identity = [&](std::size_t i) { return p.level[i] > 0 ? p.parent_id[i] : p.id[i]; };
  const auto& b = sim.bonds();
  std::size_t violations = 0;
  for (std::size_t x = 0; x < b.particles(); ++x)
    for_each_own_bond(b, x, [&](std::int64_t k, std::size_t y) {
      const auto P = identity(x), Q = identity(y);
      if (b.own_intact(k) && P != Q && broken.count({P, Q})) ++violations;
    });
  std::printf("no-healing after a run: %zu broken pairs before, %lld broken bonds after\n",
              broken.size() / 2, static_cast<long long>(sim.broken_bonds()));
  EXPECT_EQ(violations, 0u);
  EXPECT_EQ(intact_crossing(sim, {s.cracks[0]}), 0u);
  EXPECT_GE(sim.broken_bonds(), 300);
}

TEST(Refinement, NoHealingRuleOnSegments) {
  using geometry::Vec3;
  EXPECT_TRUE(refine::segments_cross_properly({0, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 0, 0}));
  EXPECT_FALSE(
      refine::segments_cross_properly({0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 1, 0}));  // touch
  EXPECT_FALSE(refine::segments_cross_properly({0, 0, 0}, {1, 0, 0}, {0.5, 0, 0}, {2, 0, 0}));
  EXPECT_FALSE(refine::segments_cross_properly({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}));
}

}  // namespace
}  // namespace dhpd
