// Probes (`output.probes`, docs/scenes.md): the displacement and velocity of the particle nearest
// to a named point, as columns of history.csv (docs/outputs.md).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "engine/discretization/particles.hpp"

namespace dhpd::io {

struct Probe {
  std::string name;
  geometry::Vec3 at{0, 0, 0};
};

/// The history columns of the probes: NAME_ux, NAME_uy[, NAME_uz], NAME_vx, NAME_vy[, NAME_vz].
std::vector<std::string> probe_columns(const std::vector<Probe>& probes, int dim);

/// The particle whose reference position is nearest to `at` (ties: the smaller id). Found again
/// at every row, so a refinement event that splits it is followed by its nearest child.
std::size_t nearest_particle(const ParticleStore& p, const geometry::Vec3& at);

/// The values of probe_columns now, in that order.
std::vector<double> probe_values(const ParticleStore& p, const std::vector<Probe>& probes);

}  // namespace dhpd::io
