// Small builders shared by the refinement tests (test-only code).
#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

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
  return s;
}

/// The children of an event and their parents' slots before it, found by ids: a child is a
/// particle of `after` whose parent_id names a particle of `before` (the store just before the
/// event). Children in ascending slot order.
struct Family {
  std::vector<std::int32_t> child_slot, parent_slot;
};
inline Family family_of_event(const ParticleStore& before, const ParticleStore& after) {
  std::unordered_map<std::int32_t, std::int32_t> slot_of_id;
  for (std::size_t i = 0; i < before.size(); ++i)
    slot_of_id[before.id[i]] = static_cast<std::int32_t>(i);
  Family f;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const auto it = slot_of_id.find(after.parent_id[i]);
    if (after.parent_id[i] < 0 || it == slot_of_id.end()) continue;
    f.child_slot.push_back(static_cast<std::int32_t>(i));
    f.parent_slot.push_back(it->second);
  }
  return f;
}

/// Every particle index of the current generation.
inline std::vector<std::int32_t> all_particles(const Simulation& sim) {
  std::vector<std::int32_t> all(sim.particles().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
  return all;
}

}  // namespace dhpd::test
