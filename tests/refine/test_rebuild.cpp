// Incremental rebuild = from-scratch rebuild (issue 4): after random split sets, every bond row,
// partial volume, dual row, interaction row and intact flag equals what a full rebuild on the same
// particles and the no-healing rule applied from scratch give, and the edited bond and dual lists
// are consistent in themselves (tests/support/bonds.hpp); a re-sort keeps them too.
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

/// Own bonds of one owner as (neighbour id, length, β, intact), sorted: comparable across
/// numberings.
using BondKey = std::tuple<std::int32_t, double, double, int>;
std::vector<std::vector<BondKey>> rows_by_id(const BondList& b, const ParticleStore& p) {
  std::vector<std::vector<BondKey>> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (auto k = b.begin(i); k < b.end(i); ++k)
      out[i].emplace_back(p.id[b.neighbor[k]], b.length[k], b.weight[k], b.intact[k]);
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
}

/// Owners (ids) in each dual row, sorted.
std::vector<std::vector<std::int32_t>> duals_by_id(const DualList& d, const BondList& b,
                                                   const ParticleStore& p) {
  std::vector<std::vector<std::int32_t>> out(p.size());
  for (std::size_t j = 0; j < p.size(); ++j) {
    for (auto k = d.begin(j); k < d.end(j); ++k) {
      const auto bond = d.bond[k];
      EXPECT_EQ(b.neighbor[bond], static_cast<std::int32_t>(j));
      out[j].push_back(p.id[b.owner[bond]]);
    }
    std::sort(out[j].begin(), out[j].end());
  }
  return out;
}

using EntryKey = std::tuple<std::int32_t, double, double, float, int>;
/// A break threshold that compares equal to itself (kNeverBreaks is NaN).
float comparable(float threshold) {
  return std::isnan(threshold) ? HUGE_VALF : threshold;
}
std::vector<std::vector<EntryKey>> interactions_by_id(const InteractionList& il,
                                                      const ParticleStore& p) {
  std::vector<std::vector<EntryKey>> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (auto k = il.begin(i); k < il.end(i); ++k)
      out[i].emplace_back(p.id[il.other[k]], il.inv_length[k], il.coefficient[k],
                          comparable(il.break_at[k]), il.alive[k]);
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
}

/// Checks that the simulation's rows equal a from-scratch build of its particles, with the
/// intact flags of `apply_no_healing` against the previous generation. Returns bonds compared.
std::size_t expect_equals_from_scratch(const Simulation& sim, const refine::RefinementEvent& ev,
                                       const BondList& old_b, const ParticleStore& old_p) {
  const auto& p = sim.particles();
  std::vector<std::int32_t> previous(p.size());
  std::vector<std::uint8_t> born(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) previous[i] = static_cast<std::int32_t>(i);
  const auto fam = test::family_of_event(old_p, p);
  for (std::size_t c = 0; c < fam.child_slot.size(); ++c) {
    previous[fam.child_slot[c]] = fam.parent_slot[c];
    born[fam.child_slot[c]] = 1;
  }
  BondList fresh = build_bonds(p, sim.setup().partial_volume, sim.setup().cracks);
  refine::apply_no_healing(fresh, p, previous, born, old_b, old_p);
  for (std::size_t i = 0; i < p.size(); ++i)  // the second birth rule
    for (auto k = fresh.begin(i); k < fresh.end(i); ++k)
      if (fresh.intact[k] &&
          refine::starts_overstretched(p, i, static_cast<std::size_t>(fresh.neighbor[k]),
                                       fresh.length[k], sim.critical_stretch()[i]))
        fresh.intact[k] = 0;
  const DualList fresh_dual = build_dual(fresh);
  const auto fresh_il = build_interactions(
      {sim.setup().model, fresh, fresh_dual, p, sim.micromodulus(), sim.critical_stretch()});
  EXPECT_EQ(sim.bonds().size(), fresh.size());
  EXPECT_EQ(sim.interactions().size(), fresh_il.size());
  // The incrementally edited lists are consistent in themselves (garbage and moved rows included).
  test::expect_consistent(sim.bonds(), sim.dual(), p.size(), "after the event");
  // Rows that differ (printing whole rows would drown the report).
  auto differing = [](const auto& x, const auto& y) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < x.size(); ++i) n += x[i] != y[i];
    return n;
  };
  EXPECT_EQ(differing(rows_by_id(sim.bonds(), p), rows_by_id(fresh, p)), 0u) << "bond rows";
  EXPECT_EQ(differing(duals_by_id(sim.dual(), sim.bonds(), p), duals_by_id(fresh_dual, fresh, p)),
            0u)
      << "dual rows";
  EXPECT_EQ(differing(interactions_by_id(sim.interactions(), p), interactions_by_id(fresh_il, p)),
            0u)
      << "interaction rows";
  return fresh.size();
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
      const BondList old_b = sim.bonds();
      const ParticleStore old_p = sim.particles();
      const auto ev = refine::split(sim, random_parents(sim, rng, 0.008, 2));
      ASSERT_GT(ev.children, 0u);
      ASSERT_FALSE(ev.resorted);
      started_broken += static_cast<std::size_t>(ev.started_broken);
      compared += expect_equals_from_scratch(sim, ev, old_b, old_p);
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
    const BondList old_b = sim.bonds();
    const ParticleStore old_p = sim.particles();
    const auto ev = refine::split(sim, random_parents(sim, rng, 0.004, 1));
    ASSERT_GT(ev.children, 0u);
    std::printf("3D event: %zu parents, %zu rows, %lld started broken, %.3f s\n", ev.parents,
                ev.rows_rebuilt, static_cast<long long>(ev.started_broken), ev.seconds);
    compared += expect_equals_from_scratch(sim, ev, old_b, old_p);
  }
  std::printf("3D incremental = scratch: %zu bonds compared\n", compared);
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
    std::vector<std::pair<std::int32_t, std::vector<BondKey>>> rows;
    const auto r = rows_by_id(x.bonds(), q);
    for (std::size_t i = 0; i < q.size(); ++i) rows.emplace_back(q.id[i], r[i]);
    std::sort(rows.begin(), rows.end());
    return rows;
  };
  auto forces = [](const Simulation& x) {
    const auto& q = x.particles();
    std::vector<std::pair<std::int32_t, double>> f;
    for (std::size_t i = 0; i < q.size(); ++i) f.emplace_back(q.id[i], q.force_density[1][i]);
    std::sort(f.begin(), f.end());
    return f;
  };
  const auto rows_before = by_id(sim);
  const auto f_before = forces(sim);
  const auto broken = sim.broken_bonds();
  const auto arena_before = sim.bonds().slots();
  const double seconds = sim.compact();
  EXPECT_EQ(by_id(sim), rows_before);
  EXPECT_EQ(sim.broken_bonds(), broken);
  EXPECT_EQ(sim.bonds().slots(), sim.bonds().size());  // compacted
  const auto f_after = forces(sim);
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < f_after.size(); ++k) {
    ASSERT_EQ(f_after[k].first, f_before[k].first);
    worst = std::max(worst, std::abs(f_after[k].second - f_before[k].second));
    scale = std::max(scale, std::abs(f_before[k].second));
  }
  std::printf("re-sort of %zu particles: %.3f ms, arena %zu -> %zu slots, max force change %.1e\n",
              p.size(), 1e3 * seconds, arena_before, sim.bonds().slots(), worst / scale);
  EXPECT_LE(worst, 1e-12 * scale);
}

}  // namespace
}  // namespace dhpd
