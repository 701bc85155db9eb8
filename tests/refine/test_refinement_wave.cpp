// A wave crossing a coarse/fine boundary that refinement creates mid-run (issue 4; CMAME 2017 §4
// for the measure): the reflection is u_adaptive − u_reference at a coarse-side probe, where the
// reference bar is never refined.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/simulation.hpp"
#include "refine/event.hpp"

namespace dhpd {
namespace {

constexpr double kWaveSpeed = 1000.0;    // sqrt(E / rho)
constexpr double kCoarse = 1.0 / 960.0;  // the pulse (width 0.0316) spans ~30 cells
constexpr double kInterface = 0.5;       // particles right of it are split at step 10
constexpr double kProbe = 0.42;

SimulationSetup bar(ForceModel model) {
  SimulationSetup s;
  s.section = {1, PlaneMode::Stress, 1, 1e-4};
  s.model = model;
  s.materials = {{1.0e6, 1.0, 0}};
  using geometry::Box;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {1, 0, 0}}, kCoarse, 0}}, 1);
  InitialCondition ic;  // u(x, 0) = 0.002 exp(−(x − 0.3)² / w²), w² = 1/1000 (eq. 31's pulse)
  ic.region = Box{{0, 0, 0}, {1, 0, 0}};
  ic.displacement = Vec3{0.002, 0, 0};
  ic.gaussian_width = std::sqrt(1e-3);
  ic.gaussian_center = {0.3, 0, 0};
  s.initial_conditions = {ic};
  s.fixed_dt = 0.25 * kCoarse / kWaveSpeed;  // stable for the children too; same for both runs
  return s;
}

/// u(t) at the probe (found by its stable id) every step up to `t_end`.
std::vector<double> probe_history(ForceModel model, bool refine, double t_end) {
  Simulation sim(bar(model));
  std::int32_t probe_id = -1;
  {
    const auto& p = sim.particles();
    double best = 1e9;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (std::abs(p.reference_position[0][i] - kProbe) < best)
        best = std::abs(p.reference_position[0][i] - kProbe), probe_id = p.id[i];
  }
  std::vector<double> u;
  for (int k = 1; sim.time() < t_end; ++k) {
    sim.step();
    if (refine && k == 10) {
      std::vector<std::int32_t> parents;
      const auto& p = sim.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (p.reference_position[0][i] > kInterface)
          parents.push_back(static_cast<std::int32_t>(i));
      const auto ev = refine::split(sim, parents);
      EXPECT_EQ(ev.children, 2 * parents.size());
    }
    const auto& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.id[i] == probe_id) u.push_back(p.displacement[0][i]);
  }
  return u;
}

double reflection(ForceModel model) {
  // The right-going half of the pulse passes the probe by t ≈ 0.20/c; its reflection from the
  // interface returns by ≈ 0.24/c; the left-going half, reflected at x = 0, arrives after 0.6/c.
  const double t_end = 0.55 / kWaveSpeed, dt = 0.25 * kCoarse / kWaveSpeed;
  const auto adaptive = probe_history(model, true, t_end);
  const auto reference = probe_history(model, false, t_end);
  double incident = 0, reflected = 0;
  for (std::size_t k = 0; k < std::min(adaptive.size(), reference.size()); ++k) {
    const double t = static_cast<double>(k + 1) * dt;
    if (t < 0.22 / kWaveSpeed)
      incident = std::max(incident, std::abs(reference[k]));
    else
      reflected = std::max(reflected, std::abs(adaptive[k] - reference[k]));
  }
  EXPECT_NEAR(incident, 0.001, 1e-4);  // half the initial pulse runs each way
  return reflected / incident;
}

// Measured: 1.52 % for DH-PD. (Classical BB-PD gives 1.56 % here: a 2x jump under a well
// resolved pulse is a mild test of ghost forces; the 10x bar in test_wave_bar.cpp is the sharp
// one.)
TEST(RefinementWave, BoundaryCreatedMidRunReflectsLessThanFivePercent) {
  const double dh = reflection(ForceModel::DualHorizon);
  std::printf(
      "wave through a refinement boundary made at step 10 (2x jump): reflected/incident "
      "DH-PD %.2f %%\n",
      100 * dh);
  EXPECT_LT(dh, 0.05);
}

}  // namespace
}  // namespace dhpd
