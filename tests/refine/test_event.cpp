// Refinement events (docs/theory.md §13; IJNME 2016 §5.3): a split conserves mass, volume and
// momentum and reports the kinetic energy its mapping adds; refining everything at t = 0 equals
// starting fine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "tests/support/setups.hpp"

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
    if (mapping == refine::StateMapping::Copy) {
      EXPECT_EQ(spread, 0.0);
    }
    if (mapping != refine::StateMapping::Copy) {
      EXPECT_GT(spread, 1e-5 * before.e.kinetic);
    }
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
    EXPECT_EQ(coarse.bonds().bond_count(), fine.bonds().bond_count());
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
        std::string(to_string(pv)).c_str(), a.size(), fine.bonds().bond_count(), diff / umax,
        ec.kinetic / ef.kinetic - 1, ec.strain / ef.strain - 1);
    EXPECT_GT(umax, 0.0);
    EXPECT_LE(diff, 1e-9 * umax);
  }
}
}  // namespace
}  // namespace dhpd
