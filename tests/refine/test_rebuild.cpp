// Incremental rebuild = from-scratch rebuild (issue 4): after random split sets, every bond row
// (neighbours, lengths, own and dual bonds, intact states, stiffness, break thresholds) equals what
// a full rebuild on the same particles and the no-healing rule applied from scratch give, and the
// edited rows are consistent in themselves (tests/support/bonds.hpp); a re-sort keeps them too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <tuple>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "refine/no_healing.hpp"
#include "tests/support/bonds.hpp"
#include "tests/support/engine.hpp"
#include "tests/support/refine.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

/// Every entry of every row as (other's id, 1/|ξ|, flags, stiffness), sorted: comparable across
/// numberings.
using EntryKey = std::tuple<std::int32_t, double, int, float>;
std::vector<std::vector<EntryKey>> rows_by_id(const BondRows& b, const ParticleStore& p) {
  std::vector<std::vector<EntryKey>> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (auto k = b.begin(i); k < b.end(i); ++k)
      out[i].emplace_back(p.id[b.other[k]], b.inverse_length(k), b.flags[k], b.stiffness[k]);
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
}

/// Checks that the simulation's rows equal a from-scratch build of its particles, with the
/// intact flags of `apply_no_healing` against the previous generation (and the level-interface
/// factors the events solved, which depend on their order). Returns bonds compared.
std::size_t expect_equals_from_scratch(const Simulation& sim, const BondRows& old_b,
                                       const ParticleStore& old_p) {
  const auto& p = sim.particles();
  std::vector<std::int32_t> previous(p.size());
  std::vector<std::uint8_t> born(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) previous[i] = static_cast<std::int32_t>(i);
  const auto fam = test::family_of_event(old_p, p);
  for (std::size_t c = 0; c < fam.child_slot.size(); ++c) {
    previous[fam.child_slot[c]] = fam.parent_slot[c];
    born[fam.child_slot[c]] = 1;
  }
  const auto& now = sim.bonds();
  BondRows fresh = build_bond_rows(p, sim.setup().partial_volume, sim.setup().cracks);
  refine::apply_no_healing(fresh, p, previous, born, old_b, old_p);
  for (std::size_t i = 0; i < p.size(); ++i)  // the second birth rule
    for_each_own_bond(fresh, i, [&](std::int64_t k, std::size_t j) {
      if (!fresh.own_intact(k) || !refine::starts_overstretched(p, i, j, fresh.inverse_length(k),
                                                                sim.critical_stretch()[i]))
        return;
      fresh.flags[k] &= static_cast<std::uint8_t>(~kOwnIntact);
      const auto d = fresh.find(j, static_cast<std::int32_t>(i));
      fresh.flags[d] &= static_cast<std::uint8_t>(~kDualIntact);
    });
  if (!now.factor.empty()) {  // the same slots: take the factors the events solved
    fresh.factor.assign(fresh.other.size(), 1.0f);
    for (std::size_t i = 0; i < p.size(); ++i)
      for_each_own_bond(fresh, i, [&](std::int64_t k, std::size_t j) {
        const auto e = now.find(i, static_cast<std::int32_t>(j));
        if (e >= 0) fresh.factor[k] = now.factor[e];
      });
  }
  fresh.stiffness_scale = now.stiffness_scale;
  refresh_rows(fresh, sim.bond_constants(), false);
  EXPECT_EQ(now.bond_count(), fresh.bond_count());
  EXPECT_EQ(now.live, fresh.live);
  // The incrementally edited rows are consistent in themselves (garbage and moved rows included).
  test::expect_consistent(now, p.size(), "after the event",
                          sim.setup().model == ForceModel::DualHorizon);
  // Rows that differ (printing whole rows would drown the report).
  const auto a = rows_by_id(now, p), b = rows_by_id(fresh, p);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differing += a[i] != b[i];
  EXPECT_EQ(differing, 0u) << "bond rows";
  EXPECT_EQ(now.break_ratio2, fresh.break_ratio2);
  return fresh.bond_count();
}

/// Random parents among the particles of level < max_level (about `fraction` of them, clustered
/// around a random point so that events touch a neighbourhood, as in a real run).
std::vector<std::int32_t> random_parents(const Simulation& sim, std::mt19937& rng, double radius,
                                         int max_level) {
  const auto& p = sim.particles();
  std::uniform_int_distribution<std::size_t> pick(0, p.size() - 1);
  const auto centre = pick(rng);
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d2 = 0.0;
    for (int a = 0; a < p.dim(); ++a)
      d2 += std::pow(p.reference_position[a][i] - p.reference_position[a][centre], 2);
    if (d2 < radius * radius && p.level[i] < max_level && rng() % 4 != 0)
      out.push_back(static_cast<std::int32_t>(i));
  }
  return out;
}

TEST(RefinementIncremental, RandomEventsEqualFromScratchInEveryPartialVolumeMode) {
  for (const auto pv : {PartialVolume::None, PartialVolume::Linear, PartialVolume::Exact}) {
    auto s = test::pulled_cracked_plate(1e-3);
    s.partial_volume = pv;
    s.resort_fraction = 0.0;         // compare the incremental rows themselves
    s.interface_correction = false;  // its factors depend on the events' order (own test)
    Simulation sim(s);
    for (int k = 0; k < 300 && sim.broken_bonds() < 150; ++k) sim.run_steps(10);
    ASSERT_GE(sim.broken_bonds(), 150) << to_string(pv);
    std::mt19937 rng(11);
    std::size_t compared = 0, started_broken = 0;
    for (int event = 0; event < 4; ++event) {
      const BondRows old_b = sim.bonds();
      const ParticleStore old_p = sim.particles();
      const auto ev = refine::split(sim, random_parents(sim, rng, 0.008, 2));
      ASSERT_GT(ev.children, 0u);
      ASSERT_FALSE(ev.resorted);
      started_broken += static_cast<std::size_t>(ev.started_broken);
      compared += expect_equals_from_scratch(sim, old_b, old_p);
      sim.run_steps(5);
    }
    std::printf(
        "incremental = scratch (%s): %zu bonds compared over 4 events, %zu started broken\n",
        std::string(to_string(pv)).c_str(), compared, started_broken);
    EXPECT_GT(started_broken, 0u);
  }
}

TEST(RefinementIncremental, ThreeDimensionalEventsEqualFromScratch) {
  auto s = test::lifted_block_3d();
  s.resort_fraction = 0.0;
  Simulation sim(s);
  sim.step();
  ASSERT_GT(sim.broken_bonds(), 0);
  std::mt19937 rng(5);
  std::size_t compared = 0;
  for (int event = 0; event < 3; ++event) {
    const BondRows old_b = sim.bonds();
    const ParticleStore old_p = sim.particles();
    const auto ev = refine::split(sim, random_parents(sim, rng, 0.004, 1));
    ASSERT_GT(ev.children, 0u);
    std::printf("3D event: %zu parents, %zu rows, %lld started broken, %.3f s\n", ev.parents,
                ev.rows_rebuilt, static_cast<long long>(ev.started_broken), ev.seconds);
    compared += expect_equals_from_scratch(sim, old_b, old_p);
  }
  std::printf("3D incremental = scratch: %zu bonds compared\n", compared);
}

/// (id, f_y) of every particle, by id.
std::vector<std::pair<std::int32_t, double>> forces_by_id(const Simulation& x) {
  const auto& q = x.particles();
  std::vector<std::pair<std::int32_t, double>> f;
  for (std::size_t i = 0; i < q.size(); ++i) f.emplace_back(q.id[i], q.force_density[1][i]);
  std::sort(f.begin(), f.end());
  return f;
}

TEST(RefinementIncremental, ResortKeepsEveryBondAndTheForces) {
  auto s = test::pulled_cracked_plate(1e-3);
  s.resort_fraction = 0.0;
  Simulation sim(s);
  for (int k = 0; k < 300 && sim.broken_bonds() < 100; ++k) sim.run_steps(10);
  std::mt19937 rng(3);
  refine::split(sim, random_parents(sim, rng, 0.01, 1));
  refine::split(sim, random_parents(sim, rng, 0.01, 2));
  const auto& p = sim.particles();
  auto by_id = [](const Simulation& x) {
    const auto& q = x.particles();
    std::vector<std::pair<std::int32_t, std::vector<EntryKey>>> rows;
    const auto r = rows_by_id(x.bonds(), q);
    for (std::size_t i = 0; i < q.size(); ++i) rows.emplace_back(q.id[i], r[i]);
    std::sort(rows.begin(), rows.end());
    return rows;
  };
  const auto forces = forces_by_id;
  const auto rows_before = by_id(sim);
  const auto f_before = forces(sim);
  const auto broken = sim.broken_bonds();
  const auto arena_before = sim.bonds().rows.arena;
  const double seconds = sim.compact();
  EXPECT_EQ(by_id(sim), rows_before);
  EXPECT_EQ(sim.broken_bonds(), broken);
  EXPECT_EQ(sim.bonds().rows.arena, sim.bonds().live);  // compacted
  const auto f_after = forces(sim);
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < f_after.size(); ++k) {
    ASSERT_EQ(f_after[k].first, f_before[k].first);
    worst = std::max(worst, std::abs(f_after[k].second - f_before[k].second));
    scale = std::max(scale, std::abs(f_before[k].second));
  }
  std::printf(
      "re-sort of %zu particles: %.3f ms, arena %lld -> %lld slots, max force change %.1e\n",
      p.size(), 1e3 * seconds, static_cast<long long>(arena_before),
      static_cast<long long>(sim.bonds().rows.arena), worst / scale);
  EXPECT_LE(worst, 1e-12 * scale);
}

}  // namespace
}  // namespace dhpd

namespace dhpd {
namespace {

// The ordinary state-based family's events recompute every particle's internal force (θ couples
// each row to its partners): the forces they leave, the loads' body forces included on particles
// the event did not touch, are those of a pass from scratch (the re-sort's).
TEST(RefinementIncremental, StateBasedEventsLeaveTheForcesOfAFullPass) {
  auto s = test::pulled_cracked_plate(1e-3);
  s.family = ModelFamily::OrdinaryState;
  for (auto& m : s.materials) m.nu = 0.3;
  s.resort_fraction = 0.0;
  Simulation sim(s);
  sim.run_steps(20);
  std::mt19937 rng(3);
  refine::split(sim, random_parents(sim, rng, 0.004, 1));
  const auto after_event = forces_by_id(sim);
  sim.compact();  // renumbers and computes every force again
  const auto full = forces_by_id(sim);
  double worst = 0.0, scale = 0.0;
  ASSERT_EQ(after_event.size(), full.size());
  for (std::size_t k = 0; k < full.size(); ++k) {
    ASSERT_EQ(after_event[k].first, full[k].first);
    worst = std::max(worst, std::abs(after_event[k].second - full[k].second));
    scale = std::max(scale, std::abs(full[k].second));
  }
  EXPECT_LE(worst, 1e-12 * scale) << worst / scale;
}

}  // namespace
}  // namespace dhpd
