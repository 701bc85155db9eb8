// Names of the run-wide choices, as the scene file spells them.
#include "engine/settings.hpp"

namespace dhpd {

std::string_view to_string(ForceModel m) {
  switch (m) {
    case ForceModel::DualHorizon:
      return "dual-horizon";
    case ForceModel::ConstantHorizon:
      return "constant-horizon";
    default:
      return "classical-variable";
  }
}
std::string_view to_string(PartialVolume p) {
  return p == PartialVolume::None ? "none" : "linear";
}
std::string_view to_string(PlaneMode p) {
  return p == PlaneMode::Stress ? "stress" : "strain";
}

}  // namespace dhpd
