// Settled particles (refine/settled.*, docs/theory.md §13.2): the memo kept by particle id agrees
// with a brute-force scan of every particle's buffer after events that settle particles (coarse
// neighbours split to max_level) and after events that unsettle them (children below max_level
// next to them); and the refiner, which skips settled particles' triggers and buffers, picks the
// same parents as the selection without the memo.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/refiner.hpp"
#include "refine/settled.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::Box;
using test::plate;

/// Settled by definition: at max_level with every other particle within buffer × δ_i at max_level.
std::vector<std::uint8_t> settled_by_scan(const ParticleStore& p, double buffer, int max_level) {
  std::vector<std::uint8_t> out(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.level[i] < max_level) continue;
    const double r = buffer * p.horizon[i];
    bool all = true;
    for (std::size_t j = 0; j < p.size() && all; ++j) {
      double d2 = 0.0;
      for (int a = 0; a < p.dim(); ++a)
        d2 += (p.reference_position[a][j] - p.reference_position[a][i]) *
              (p.reference_position[a][j] - p.reference_position[a][i]);
      all = j == i || d2 >= r * r || p.level[j] >= max_level;
    }
    out[i] = all ? 1 : 0;
  }
  return out;
}

std::vector<std::int32_t> inside(const ParticleStore& p, const Box& box, int level) {
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.level[i] == level && box.contains(point_of(p.reference_position, i), p.dim()))
      out.push_back(static_cast<std::int32_t>(i));
  return out;
}

std::int32_t next_id(const ParticleStore& p) {
  return *std::max_element(p.id.begin(), p.id.end()) + 1;
}

TEST(SettledParticles, AgreeWithAScanOfEveryBufferThroughEvents) {
  // Events without grading (refine::split directly), so that children below max_level can land
  // next to settled particles: a square split twice (level 2 next to level 0), then the ring
  // around it split once (level-1 children unsettle the square's second layer), then again
  // (the ring at level 2 settles the square's edge).
  const double buffer = 1.0;
  const int max_level = 2;
  Simulation sim(plate(1e-3, 0.02, 0.02));
  refine::EventSearch search;
  refine::SettledParticles settled(buffer, max_level);
  const Box square{{0.008, 0.008, 0}, {0.012, 0.012, 0}};
  const Box ring{{0.007, 0.007, 0}, {0.013, 0.013, 0}};
  auto split = [&](const Box& box, int level) {
    const auto first = next_id(sim.particles());
    refine::split(sim, inside(sim.particles(), box, level), refine::StateMapping::Linear, &search);
    settled.after_event(sim.particles(), search.grid(sim), first);
  };
  auto check = [&](const char* when) {
    const auto& p = sim.particles();
    const auto memo = settled.update(p, search.grid(sim));
    const auto scan = settled_by_scan(p, buffer, max_level);
    const auto count = std::count(scan.begin(), scan.end(), 1);
    std::printf("%s: %zu particles, %ld settled\n", when, p.size(), static_cast<long>(count));
    EXPECT_EQ(memo, scan) << when;
    return count;
  };
  split(square, 0);
  split(square, 1);
  const auto square_only = check("square at level 2");
  EXPECT_GT(square_only, 0);
  split(ring, 0);
  const auto ring_below = check("ring at level 1");
  EXPECT_LT(ring_below, square_only);
  EXPECT_GT(ring_below, 0);
  split(ring, 1);
  EXPECT_GT(check("ring at level 2"), square_only);
}

TEST(SettledParticles, TheRefinerPicksTheParentsItWouldWithoutThem) {
  // A plate strained to 0.6 s0 everywhere, with a zone refined to max_level: every particle
  // reaches the stretch trigger (0.5 s0), settled ones included. The refiner skips the settled
  // ones' stretch test and buffer; the full selection, run on an identical simulation, splits
  // the same parents.
  const auto s = test::strained_plate(0.02, 0.02, 0.6);
  refine::Settings set;
  set.trigger.stretch = 0.5;
  set.buffer = 1.0;
  set.zones = {Box{{0.004, 0.004, 0}, {0.016, 0.016, 0}}};
  Simulation with_memo(s), without(s);
  refine::Refiner refiner(set);
  refiner.refine_zones(with_memo);
  refine::Refiner(set).refine_zones(without);
  const auto marked_by_all = refine::triggered(without, set.trigger);
  auto marked = marked_by_all;
  refine::add_buffer(without.particles(), set.buffer, marked);
  const auto expected = refine::graded_parents(without, marked, set.max_level);
  refine::EventSearch search;
  refine::SettledParticles settled(set.buffer, set.max_level);
  const auto mask = settled.update(with_memo.particles(), search.grid(with_memo));
  const auto skipped = std::count(mask.begin(), mask.end(), 1);
  std::printf("%ld of %zu particles settled, %zu parents expected\n", static_cast<long>(skipped),
              with_memo.particles().size(), expected.size());
  ASSERT_GT(skipped, 0);
  ASSERT_FALSE(expected.empty());
  const auto first = next_id(with_memo.particles());
  std::vector<std::int32_t> expected_ids;
  for (const auto q : expected) expected_ids.push_back(with_memo.particles().id[q]);
  const auto event = refiner.check(with_memo);
  EXPECT_EQ(event.parents, expected.size());
  std::vector<std::int32_t> split_ids;  // the parents named by the new children
  const auto& p = with_memo.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.id[i] >= first) split_ids.push_back(p.parent_id[i]);
  std::sort(split_ids.begin(), split_ids.end());
  split_ids.erase(std::unique(split_ids.begin(), split_ids.end()), split_ids.end());
  std::sort(expected_ids.begin(), expected_ids.end());
  EXPECT_EQ(split_ids, expected_ids);
}

}  // namespace
}  // namespace dhpd
