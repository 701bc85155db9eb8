// The point fields of an output frame, gathered from the simulation by name.
#pragma once
#include <string>
#include <vector>

#include "engine/simulation.hpp"
#include "tools/output/vtk_writer.hpp"

namespace dhpd::io {

/// Reference positions as 3 doubles per particle.
std::vector<double> frame_points(const Simulation& sim);
/// The requested fields (names from scene::default_fields() and scene::optional_fields()).
std::vector<PointField> frame_fields(Simulation& sim, const std::vector<std::string>& names);

}  // namespace dhpd::io
