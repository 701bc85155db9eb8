// Refinement events (docs/theory.md §13; IJNME 2016 §5.3): conservation through a split, refining
// everything at t = 0 equals starting fine, no healing, triggers and grading.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>

#include "refine/no_healing.hpp"
#include "refine/refiner.hpp"
#include "refine/split_plan.hpp"
#include "tests/refine_support.hpp"
#include "tests/support.hpp"

namespace dhpd {
namespace {

using test::all_particles;
using test::Box;
using test::plate;

struct Totals {
  double mass = 0, volume = 0;
  Energies e;
};

Totals totals(Simulation& sim) {
  Totals t;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i) t.mass += p.density[i] * p.volume[i];
  for (std::size_t i = 0; i < p.size(); ++i) t.volume += p.volume[i];
  t.e = sim.energies();
  return t;
}

/// ½ Σ_c m_c |v_c − v_parent|² over the children of the last event: the kinetic energy a
/// momentum-conserving mapping adds (Σ m_c v_c = m_q v_q makes the cross term vanish).
double spread_energy(const ParticleStore& p, const std::map<std::int32_t, geometry::Vec3>& v_of) {
  double e = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const auto parent = v_of.find(p.parent_id[k]);
    if (p.level[k] != 1 || parent == v_of.end()) continue;
    for (int a = 0; a < 2; ++a)
      e += 0.5 * p.density[k] * p.volume[k] * std::pow(p.velocity[a][k] - parent->second[a], 2);
  }
  return e;
}

TEST(Refinement, SplitConservesMassVolumeMomentumAndKineticEnergy) {
  // copy conserves kinetic energy; linear and quadratic add exactly the spread of the children's
  // velocities about their parent's (what the resolved gradient implies) and report it.
  for (const auto mapping : {refine::StateMapping::Copy, refine::StateMapping::Linear,
                             refine::StateMapping::Quadratic}) {
    auto s = plate(1e-3, 0.03, 0.02);
    s.effects.fracture = true;
    InitialCondition ic;
    ic.region = Box{{0, 0, 0}, {0.03, 0.02, 0}};
    ic.velocity = geometry::Vec3{3.0, -2.0, 0};
    ic.gaussian_width = 0.006;
    ic.gaussian_center = {0.012, 0.008, 0};
    ic.strain = geometry::Vec3{2e-3, -1e-3, 0};
    s.initial_conditions = {ic};
    Simulation sim(s);
    sim.run_steps(30);
    std::mt19937 rng(7);
    std::vector<std::int32_t> parents;
    std::map<std::int32_t, geometry::Vec3> v_of;
    for (const auto i : all_particles(sim))
      if (rng() % 3 == 0) {
        parents.push_back(i);
        v_of[sim.particles().id[i]] = point_of(sim.particles().velocity, i);
      }
    const auto before = totals(sim);
    const auto ev = refine::split(sim, parents, mapping);
    const auto after = totals(sim);
    EXPECT_EQ(ev.children, 4 * parents.size());
    EXPECT_EQ(sim.generation(), 1);
    // Naive sums over 600 → 1800 particles: the split is exact per parent, the totals agree to
    // the round-off of summation (measured ≤ 3e-14 relative).
    const double pscale = std::hypot(before.e.momentum[0], before.e.momentum[1]);
    const double spread = spread_energy(sim.particles(), v_of);
    const double mapping_change =
        after.e.kinetic + after.e.strain - before.e.kinetic - before.e.strain;
    std::printf(
        "split (%s): relative change mass %.2e volume %.2e kinetic %.2e (spread %.2e) strain "
        "%.2e, momentum %.2e %.2e, reported mapping energy %.3e J of %.3e J\n",
        refine::mapping_name(mapping), after.mass / before.mass - 1,
        after.volume / before.volume - 1, after.e.kinetic / before.e.kinetic - 1,
        spread / before.e.kinetic, after.e.strain / before.e.strain - 1,
        (after.e.momentum[0] - before.e.momentum[0]) / pscale,
        (after.e.momentum[1] - before.e.momentum[1]) / pscale, ev.energy_change, mapping_change);
    EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
    EXPECT_NEAR(after.volume, before.volume, 1e-12 * before.volume);
    EXPECT_NEAR(after.e.kinetic - before.e.kinetic, spread, 1e-12 * before.e.kinetic);
    if (mapping == refine::StateMapping::Copy) EXPECT_EQ(spread, 0.0);
    if (mapping != refine::StateMapping::Copy) EXPECT_GT(spread, 1e-5 * before.e.kinetic);
    EXPECT_NEAR(ev.energy_change, mapping_change, 1e-9 * (before.e.kinetic + before.e.strain));
    for (int a = 0; a < 2; ++a)
      EXPECT_NEAR(after.e.momentum[a], before.e.momentum[a], 1e-12 * pscale);
    // Children: inside the parent's cell, level 1, parent id, a quarter of the volume.
    const auto& p = sim.particles();
    ASSERT_EQ(p.size(), 3 * parents.size() + 600);
    std::size_t children = 0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (p.parent_id[k] < 0) continue;
      ++children;
      EXPECT_EQ(p.level[k], 1);
      EXPECT_DOUBLE_EQ(p.spacing[k], 0.5e-3);
      EXPECT_DOUBLE_EQ(p.volume[k], 0.25 * 1e-6 * 1e-3);
    }
    EXPECT_EQ(children, ev.children);
  }
}

/// Indices sorted by reference position (rounded to a quarter of the fine spacing).
std::vector<std::size_t> by_position(const ParticleStore& p, double q) {
  std::vector<std::size_t> idx(p.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  auto key = [&](std::size_t i) {
    return std::pair{std::llround(p.reference_position[0][i] / q),
                     std::llround(p.reference_position[1][i] / q)};
  };
  std::sort(idx.begin(), idx.end(), [&](auto a, auto b) { return key(a) < key(b); });
  return idx;
}

SimulationSetup loaded_plate(double dx, PartialVolume pv) {
  auto s = plate(dx, 0.02, 0.01);
  s.partial_volume = pv;
  s.cracks = {{{{0, 0.005, 0}, {0.0103, 0.005, 0}}}};
  BoundaryCondition fixed;
  fixed.region = Box{{0, 0, 0}, {0.002, 0.01, 0}};
  BoundaryCondition pull;
  pull.kind = BoundaryCondition::Kind::Velocity;
  pull.region = Box{{0.018, 0, 0}, {0.02, 0.01, 0}};
  pull.velocity[0] = 2.0;
  BoundaryCondition top;
  top.kind = BoundaryCondition::Kind::Traction;
  top.region = Box{{0, 0.009, 0}, {0.02, 0.01, 0}};
  top.traction = {0, 5e6, 0};
  top.normal_axis = 1;
  s.boundary_conditions = {fixed, pull, top};
  return s;
}

TEST(Refinement, RefiningEverythingAtStartEqualsStartingFine) {
  for (const auto pv : {PartialVolume::Linear, PartialVolume::Exact}) {
    auto fine_setup = loaded_plate(0.5e-3, pv);
    const double dt = 0.5 * Simulation(fine_setup).critical_dt();
    fine_setup.fixed_dt = dt;
    auto coarse_setup = loaded_plate(1e-3, pv);
    coarse_setup.fixed_dt = dt;
    Simulation fine(fine_setup), coarse(coarse_setup);
    refine::split(coarse, all_particles(coarse));
    ASSERT_EQ(coarse.particles().size(), fine.particles().size());
    EXPECT_EQ(coarse.bonds().size(), fine.bonds().size());
    EXPECT_EQ(coarse.dt(), dt);
    const auto a = by_position(coarse.particles(), 0.125e-3);
    const auto b = by_position(fine.particles(), 0.125e-3);
    for (std::size_t k = 0; k < a.size(); ++k)
      for (int d = 0; d < 2; ++d)
        ASSERT_NEAR(coarse.particles().reference_position[d][a[k]],
                    fine.particles().reference_position[d][b[k]], 1e-17);
    coarse.run_steps(200);
    fine.run_steps(200);
    const auto ec = coarse.energies(), ef = fine.energies();
    EXPECT_NEAR(ec.kinetic, ef.kinetic, 1e-9 * ef.kinetic);
    EXPECT_NEAR(ec.strain, ef.strain, 1e-9 * ef.strain);
    EXPECT_NEAR(ec.external_work, ef.external_work, 1e-9 * std::abs(ef.external_work));
    double umax = 0, diff = 0;
    for (std::size_t k = 0; k < a.size(); ++k)
      for (int d = 0; d < 2; ++d) {
        const double uf = fine.particles().displacement[d][b[k]];
        umax = std::max(umax, std::abs(uf));
        diff = std::max(diff, std::abs(coarse.particles().displacement[d][a[k]] - uf));
      }
    std::printf(
        "refine-all (%s): %zu particles, %zu bonds; after 200 steps |du|/|u| %.2e, "
        "dE_kin %.2e, dE_strain %.2e\n",
        std::string(to_string(pv)).c_str(), a.size(), fine.bonds().size(), diff / umax,
        ec.kinetic / ef.kinetic - 1, ec.strain / ef.strain - 1);
    EXPECT_GT(umax, 0.0);
    EXPECT_LE(diff, 1e-9 * umax);
  }
}

geometry::Vec3 ref(const ParticleStore& p, std::size_t i) {
  return {p.reference_position[0][i], p.reference_position[1][i], 0};
}

/// Number of intact bonds whose reference segment crosses `line`.
std::size_t intact_crossing(const Simulation& sim, const geometry::Crack& line) {
  const auto& b = sim.bonds();
  std::size_t n = 0;
  for (std::size_t k = 0; k < b.slots(); ++k)  // garbage slots are never intact
    if (b.intact[k] &&
        geometry::crosses(line, ref(sim.particles(), static_cast<std::size_t>(b.owner[k])),
                          ref(sim.particles(), static_cast<std::size_t>(b.neighbor[k])), 2))
      ++n;
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
  for (std::size_t k = 0; k < old_b.slots(); ++k)
    if (old_b.neighbor[k] >= 0 && !old_b.intact[k]) {
      const auto i = old_p.id[static_cast<std::size_t>(old_b.owner[k])];
      const auto j = old_p.id[static_cast<std::size_t>(old_b.neighbor[k])];
      broken.insert({i, j}), broken.insert({j, i});
    }
  sim.update_damage();
  std::vector<std::uint8_t> marked(old_p.size(), 0);
  for (std::size_t i = 0; i < marked.size(); ++i) marked[i] = sim.particles().damage[i] > 0.0;
  refine::add_buffer(sim.particles(), 1.0, marked);
  refine::split(sim, refine::graded_parents(sim, marked, 1));
  // The previous identity of a particle: its own id when kept, its parent's id when a child.
  const auto& p = sim.particles();
  auto identity = [&](std::size_t i) { return p.level[i] > 0 ? p.parent_id[i] : p.id[i]; };
  const auto& b = sim.bonds();
  std::size_t violations = 0;
  for (std::size_t k = 0; k < b.slots(); ++k) {
    if (b.neighbor[k] < 0) continue;  // garbage slot
    const auto P = identity(static_cast<std::size_t>(b.owner[k]));
    const auto Q = identity(static_cast<std::size_t>(b.neighbor[k]));
    if (b.intact[k] && P != Q && broken.count({P, Q})) ++violations;
  }
  std::printf("no-healing after a run: %zu broken pairs before, %lld broken bonds after\n",
              broken.size() / 2, static_cast<long long>(sim.broken_bonds()));
  EXPECT_EQ(violations, 0u);
  EXPECT_EQ(intact_crossing(sim, {s.cracks[0]}), 0u);
  EXPECT_GE(sim.broken_bonds(), 300);
}

TEST(Refinement, EnergyAndStretchTriggersAtUniformCriticalStretch) {
  // u = s0 (X − o) stretches every bond by exactly s0: W_i = W_crit,i and max s = s0.
  auto s = plate(1e-3, 0.02, 0.02);
  const double s0 = critical_stretch(s.materials[0], s.section, 3.015e-3);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.02, 0.02, 0}};
  ic.strain = geometry::Vec3{s0, s0, 0};
  ic.origin = {0.01, 0.01, 0};
  s.initial_conditions = {ic};
  Simulation sim(s);
  std::vector<double> w;
  strain_energy_density(sim.bonds(), sim.particles(), sim.micromodulus(), w);
  const auto crit = refine::critical_energy_density(sim);
  const auto smax = refine::max_bond_stretch(sim);
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(w[i], crit[i], 1e-9 * crit[i]);
    EXPECT_NEAR(smax[i], s0, 1e-9 * s0);
  }
  refine::Triggers t;
  t.energy = 0.999;
  auto on = refine::triggered(sim, t);
  EXPECT_EQ(std::count(on.begin(), on.end(), 1), static_cast<long>(w.size()));
  t.energy.reset();
  t.stretch = 1.001;
  on = refine::triggered(sim, t);
  EXPECT_EQ(std::count(on.begin(), on.end(), 1), 0);
}

TEST(Refinement, LinearMappingPutsChildrenOnAUniformStrainField) {
  // u = ε (X − o): the linear mapping reproduces it at every child (the copy does not), and both
  // conserve momentum and kinetic energy because velocities are copied.
  for (const auto mapping : {refine::StateMapping::Copy, refine::StateMapping::Linear}) {
    auto s = plate(1e-3, 0.02, 0.01);
    InitialCondition ic;
    ic.region = Box{{0, 0, 0}, {0.02, 0.01, 0}};
    ic.strain = geometry::Vec3{1e-3, -4e-4, 0};
    ic.origin = {0.01, 0.005, 0};
    ic.velocity = geometry::Vec3{1.0, 2.0, 0};
    s.initial_conditions = {ic};
    Simulation sim(s);
    const auto before = sim.energies();
    const auto ev = refine::split(sim, all_particles(sim), mapping);
    const auto after = sim.energies();
    EXPECT_NEAR(after.kinetic, before.kinetic, 1e-12 * before.kinetic);
    double worst = 0.0;
    const auto& p = sim.particles();
    for (std::size_t k = p.size() - ev.children; k < p.size(); ++k)
      for (int a = 0; a < 2; ++a) {
        const double exact = (*ic.strain)[a] * (p.reference_position[a][k] - ic.origin[a]);
        worst = std::max(worst, std::abs(p.displacement[a][k] - exact));
      }
    if (mapping == refine::StateMapping::Linear) {
      EXPECT_LT(worst, 1e-15);
    } else {
      EXPECT_NEAR(worst, 0.25e-3 * 1e-3, 1e-12);  // a quarter cell times the largest strain
    }
  }
}

TEST(Refinement, GradingKeepsNeighboursWithinOneLevel) {
  refine::Settings set;
  set.max_level = 3;
  set.zones = {Box{{0.009, 0.009, 0}, {0.011, 0.011, 0}}};
  Simulation sim(plate(1e-3, 0.02, 0.02));
  const auto events = refine::Refiner(set).refine_zones(sim);
  ASSERT_EQ(events.size(), 3u);
  const auto& p = sim.particles();
  const auto& b = sim.bonds();
  EXPECT_EQ(*std::max_element(p.level.begin(), p.level.end()), 3);
  for (std::size_t k = 0; k < b.slots(); ++k)
    if (b.neighbor[k] >= 0) {
      EXPECT_LE(std::abs(p.level[static_cast<std::size_t>(b.owner[k])] -
                         p.level[static_cast<std::size_t>(b.neighbor[k])]),
                1);
    }
  const double area = std::accumulate(p.volume.begin(), p.volume.end(), 0.0) / 1e-3;
  EXPECT_NEAR(area, 4e-4, 1e-16);
}

TEST(Refinement, TriggersSplitOnlyWithinTheGivenRegions) {
  // A plate strained uniformly to 0.6 s0: the stretch trigger (0.5 s0) marks every particle;
  // `within` keeps the split to the left half, buffer included.
  auto s = plate(1e-3, 0.02, 0.01);
  s.materials[0].G0 = 135.0;
  Simulation probe(s);
  const double s0 = probe.critical_stretch()[0];
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.02, 0.01, 0}};
  ic.strain = geometry::Vec3{0.6 * s0, 0.6 * s0, 0};
  s.initial_conditions = {ic};
  refine::Settings set;
  set.trigger.stretch = 0.5;
  set.buffer = 2.0;
  for (const bool restricted : {false, true}) {
    if (restricted) set.within = {Box{{0, 0, 0}, {0.01, 0.01, 0}}};
    Simulation sim(s);
    const auto ev = refine::Refiner(set).check(sim);
    const auto& p = sim.particles();
    std::size_t outside = 0, refined = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      refined += p.level[i] > 0 ? 1 : 0;
      outside += p.level[i] > 0 && p.reference_position[0][i] > 0.01 ? 1 : 0;
    }
    std::printf("within %s: %zu parents, %zu refined particles right of x = 10 mm\n",
                restricted ? "left half" : "(none)", ev.parents, outside);
    EXPECT_EQ(ev.parents, restricted ? 100u : 200u);
    EXPECT_EQ(outside, restricted ? 0u : refined / 2);
  }
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
