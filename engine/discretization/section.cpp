// Names of the run-wide choices, as the scene file spells them; section measures (docs/theory.md
// §7).
#include "engine/discretization/section.hpp"

#include <cmath>
#include <numbers>

#include "geometry/intersection.hpp"

namespace dhpd {

std::string_view to_string(ForceModel m) {
  switch (m) {
    case ForceModel::DualHorizon:
      return "dual-horizon";
    case ForceModel::ConstantHorizon:
      return "constant-horizon";
    case ForceModel::MultiHorizon:
      return "multi-horizon";
    default:
      return "classical-variable";
  }
}
std::string_view to_string(ModelFamily f) {
  switch (f) {
    case ModelFamily::Bond:
      return "bond";
    case ModelFamily::OrdinaryState:
      return "ordinary-state";
    default:
      return "correspondence";
  }
}
std::string_view to_string(Influence w) {
  return w == Influence::Constant ? "constant" : "inverse-distance";
}
std::string_view to_string(PartialVolume p) {
  switch (p) {
    case PartialVolume::None:
      return "none";
    case PartialVolume::Linear:
      return "linear";
    default:
      return "exact";
  }
}
std::string_view to_string(PlaneMode p) {
  return p == PlaneMode::Stress ? "stress" : "strain";
}

double Section::equal_measure_radius(double volume) const {
  const double cell = cell_of_volume(volume);
  if (dim == 1) return 0.5 * cell;
  if (dim == 2) return std::sqrt(cell / std::numbers::pi);
  return std::cbrt(3.0 * cell / (4.0 * std::numbers::pi));
}

double Section::horizon_volume(double delta) const {
  return volume_of_cell(geometry::ball_measure(dim, delta));
}

}  // namespace dhpd
