// Refinement triggers (docs/theory.md §13.1): under a uniform stretch of exactly s0 the energy
// density equals its critical value and the largest bond stretch equals s0 at every particle, so
// the energy and stretch triggers fire just below and not just above it.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"
#include "refine/triggers.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

using test::Box;
using test::plate;

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
  strain_energy_density(sim.bonds(), sim.bond_constants(), w);
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
TEST(Refinement, StretchThresholdTightensWithTheLevelsStillToGo) {
  // Every bond of a uniform lattice stretched to f s0: with s* = 0.8, a particle one split from
  // max_level triggers from 0.8 s0, two splits away from 0.64 s0, three away from 0.512 s0.
  EXPECT_DOUBLE_EQ(refine::stretch_threshold(0.8, 0, 1), 0.8);
  EXPECT_DOUBLE_EQ(refine::stretch_threshold(0.8, 0, 3), 0.8 * 0.8 * 0.8);
  EXPECT_DOUBLE_EQ(refine::stretch_threshold(0.8, 2, 3), 0.8);
  EXPECT_DOUBLE_EQ(refine::stretch_threshold(0.8, 3, 3), 0.8);  // at max_level: never split
  auto s = plate(1e-3, 0.02, 0.02);
  const double s0 = critical_stretch(s.materials[0], s.section, 3.015e-3);
  refine::Triggers t;
  t.stretch = 0.8;
  for (const double f : {0.7, 0.6}) {
    InitialCondition ic;
    ic.region = Box{{0, 0, 0}, {0.02, 0.02, 0}};
    ic.strain = geometry::Vec3{f * s0, f * s0, 0};
    ic.origin = {0.01, 0.01, 0};
    s.initial_conditions = {ic};
    Simulation sim(s);
    const long n = static_cast<long>(sim.particles().size());
    for (const int max_level : {1, 2, 3}) {
      const auto on = refine::triggered(sim, t, {max_level, nullptr});
      const bool expected = f >= refine::stretch_threshold(0.8, 0, max_level);
      EXPECT_EQ(std::count(on.begin(), on.end(), 1), expected ? n : 0)
          << "stretch " << f << " s0, max_level " << max_level;
    }
  }
}

}  // namespace
}  // namespace dhpd
