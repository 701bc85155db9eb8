// Simulation setups shared by the engine tests and those above them (test-only code): glass
// plates, a pre-cracked pulled plate, a lifted 3D block, a pulsed plate, a two-part fracturing
// plate, a ringing plate; and the measured stability limit of a fixed step.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"

namespace dhpd::test {

using geometry::Box;

/// A 2D glass plate (plane stress, 1 mm thick) of lx × ly filled at spacing dx, linear β.
inline SimulationSetup plate(double dx, double lx, double ly) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1.0};
  s.materials = {{72e9, 2440, 135.0}};
  s.partial_volume = PartialVolume::Linear;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {lx, ly, 0}}, dx, 0}}, 2);
  return s;
}

/// plate(1 mm, lx, ly) strained uniformly (biaxially) to `fraction` of its bonds' critical
/// stretch at the start: every bond's stretch is fraction × s0.
inline SimulationSetup strained_plate(double lx, double ly, double fraction) {
  auto s = plate(1e-3, lx, ly);
  const double s0 = Simulation(s).critical_stretch()[0];
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {lx, ly, 0}};
  ic.strain = geometry::Vec3{fraction * s0, fraction * s0, 0};
  s.initial_conditions = {ic};
  return s;
}

/// The 50 mm × 20 mm plate with a 25 mm pre-crack at mid-height, ±12 MPa on its top and bottom
/// millimetre (zero net force), no-fail edge strips and fracture on.
inline SimulationSetup pulled_cracked_plate(double dx) {
  auto s = plate(dx, 0.05, 0.02);
  s.effects.fracture = true;
  s.cracks = {{{{0, 0.01, 0}, {0.025, 0.01, 0}}}};
  for (const double y : {0.0, 0.019}) {
    BoundaryCondition t;
    t.kind = BoundaryCondition::Kind::Traction;
    t.region = Box{{0, y, 0}, {0.05, y + 0.001, 0}};
    t.traction = {0, y > 0 ? 12e6 : -12e6, 0};
    t.normal_axis = 1;
    s.boundary_conditions.push_back(t);
  }
  s.no_fail = {Box{{0, 0, 0}, {0.05, 0.002, 0}}, Box{{0, 0.018, 0}, {0.05, 0.02, 0}}};
  return s;
}

/// An 8 × 8 × 4 mm glass block (Δx = 1 mm, linear β, fracture on) whose upper half is lifted by
/// 2 % of a spacing: the first step breaks every bond across y = 4 mm.
inline SimulationSetup lifted_block_3d() {
  SimulationSetup s;
  s.section = {3, PlaneMode::Stress, 1.0, 1.0};
  s.materials = {{72e9, 2440, 135.0}};
  s.partial_volume = PartialVolume::Linear;
  s.effects.fracture = true;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.008, 0.008, 0.004}}, 1e-3, 0}}, 3);
  InitialCondition lift;
  lift.region = Box{{0, 0.004, 0}, {0.008, 0.008, 0.004}};
  lift.displacement = geometry::Vec3{0, 2e-5, 0};
  s.initial_conditions = {lift};
  s.fixed_dt = 1e-9;  // a short first step: the lifted state breaks the bonds, not its rebound
  return s;
}

/// A 40 x 20 mm plate hit by a sharp velocity pulse (two spacings wide): much of its energy sits
/// in modes near the stable step's frequency, where plain Verlet energy swings the most.
inline SimulationSetup pulsed_plate(double safety) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1.0};
  s.materials = {{1e9, 1000, 0.0}};
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.04, 0.02, 0}}, 1e-3, 0}}, 2);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.04, 0.02, 0}};
  ic.velocity = Vec3{1.0, 0.5, 0};
  ic.gaussian_width = 2e-3;
  ic.gaussian_center = {0.02, 0.01, 0};
  s.initial_conditions = {ic};
  s.safety = safety;
  return s;
}

/// A 60 x 24 mm glass plate at 0.5 mm with a 0.25 mm middle part and a 25 mm pre-crack, torn
/// open by ±40 MPa on its top and bottom 1.5 mm, fracture on (enough particles for a thread team).
inline SimulationSetup fracturing_plate() {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.materials = {{72e9, 2440, 3.8}};
  s.partial_volume = PartialVolume::Linear;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.06, 0.024, 0}}, 5e-4, 0},
                                     {Box{{0.02, 0, 0}, {0.04, 0.024, 0}}, 2.5e-4, 0}},
                                    2);
  s.cracks = {{{{0.0, 0.012, 0}, {0.025, 0.012, 0}}}};
  BoundaryCondition top, bottom;
  top.kind = bottom.kind = BoundaryCondition::Kind::Traction;
  top.region = Box{{0, 0.0225, 0}, {0.06, 0.024, 0}};
  bottom.region = Box{{0, 0, 0}, {0.06, 0.0015, 0}};
  top.traction = {0, 40e6, 0};
  bottom.traction = {0, -40e6, 0};
  top.normal_axis = bottom.normal_axis = 1;
  s.boundary_conditions = {top, bottom};
  s.effects.fracture = true;
  return s;
}

/// |P| / Σ m |v| of a 2D simulation: its momentum against the scale of its particles' momenta.
inline double relative_momentum(Simulation& sim) {
  const auto e = sim.energies();
  double scale = 0.0;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i)
    scale += p.density[i] * p.volume[i] * std::hypot(p.velocity[0][i], p.velocity[1][i]);
  return std::hypot(e.momentum[0], e.momentum[1]) / scale;
}

/// Every particle index of the current generation.
inline std::vector<std::int32_t> all_particles(const Simulation& sim) {
  std::vector<std::int32_t> all(sim.particles().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
  return all;
}

/// A 40 × 20 mm glass plate (no G0) released from a smooth displacement bump; `two_parts` puts a
/// 2× finer part in the middle (varying horizons, dual-horizon).
inline SimulationSetup ringing_plate(bool two_parts) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.materials = {{72e9, 2440, 0}};
  std::vector<geometry::LatticePart> parts = {{Box{{0, 0, 0}, {0.04, 0.02, 0}}, 1e-3, 0}};
  if (two_parts) parts.push_back({Box{{0.015, 0, 0}, {0.025, 0.02, 0}}, 0.5e-3, 0});
  s.points = geometry::fill_lattice(parts, 2);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.04, 0.02, 0}};
  ic.displacement = Vec3{2e-6, -1e-6, 0};
  ic.gaussian_width = 0.01;
  ic.gaussian_center = {0.02, 0.01, 0};
  s.initial_conditions = {ic};
  return s;
}

/// A 0.1 m bar at 1 mm (E 72 GPa, ρ 2440) with a Gaussian displacement pulse in its middle.
inline SimulationSetup pulsed_bar_1d() {
  SimulationSetup s;
  s.section = {1, PlaneMode::Stress, 1, 1e-4};
  s.materials = {{72e9, 2440, 0}};
  s.partial_volume = PartialVolume::Linear;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.1, 0, 0}}, 1e-3, 0}}, 1);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {0.1, 0, 0}};
  ic.displacement = Vec3{2e-6, 0, 0};
  ic.gaussian_width = 0.01;
  ic.gaussian_center = {0.05, 0, 0};
  s.initial_conditions = {ic};
  return s;
}

/// An 8 × 6 × 5 mm block at 1 mm with a Gaussian displacement pulse of peak `amplitude` × (2, −1,
/// 1).
inline SimulationSetup pulsed_block_3d(double amplitude = 1e-6) {
  SimulationSetup s;
  s.section = {3, PlaneMode::Stress, 1, 1};
  s.materials = {{72e9, 2440, 0}};
  s.partial_volume = PartialVolume::Linear;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {8e-3, 6e-3, 5e-3}}, 1e-3, 0}}, 3);
  InitialCondition ic;
  ic.region = Box{{0, 0, 0}, {8e-3, 6e-3, 5e-3}};
  ic.displacement = Vec3{2 * amplitude, -amplitude, amplitude};
  ic.gaussian_width = 3e-3;
  ic.gaussian_center = {4e-3, 3e-3, 2.5e-3};
  s.initial_conditions = {ic};
  return s;
}

/// Whether `s` runs `steps` steps at a fixed dt without the guard stopping it (the load-time
/// check of a fixed dt is the scene reader's: the engine runs any dt).
inline bool stays_stable(SimulationSetup s, double dt, int steps) {
  s.fixed_dt = dt;
  Simulation sim(s);
  try {
    sim.run_steps(steps);
    sim.check_stable(sim.energies());
  } catch (const InstabilityError&) {
    return false;
  }
  return true;
}

/// The stability limit of a fixed dt, by bisection between a stable and an unstable step: runs
/// long enough that a mode 0.1 % past its limit grows from round-off to the guard's bound.
inline double measured_limit(const SimulationSetup& s, double stable, double unstable) {
  constexpr int kSteps = 1500;
  EXPECT_TRUE(stays_stable(s, stable, kSteps));
  EXPECT_FALSE(stays_stable(s, unstable, kSteps));
  for (int k = 0; k < 9; ++k) {
    const double mid = 0.5 * (stable + unstable);
    (stays_stable(s, mid, kSteps) ? stable : unstable) = mid;
  }
  return 0.5 * (stable + unstable);
}

}  // namespace dhpd::test
