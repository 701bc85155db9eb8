// Small builders shared by the refinement tests (test-only code).
#pragma once
#include <cstdint>
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

/// Every particle index of the current generation.
inline std::vector<std::int32_t> all_particles(const Simulation& sim) {
  std::vector<std::int32_t> all(sim.particles().size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
  return all;
}

}  // namespace dhpd::test
