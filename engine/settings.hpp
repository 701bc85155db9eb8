// Choices that fix the discretisation and the force model for a whole run.
#pragma once
#include <string_view>

namespace dhpd {

enum class ForceModel {
  DualHorizon,        ///< DH-PD: own bonds with C(δ_i) plus dual reactions (IJNME 2016 eq. 27)
  ConstantHorizon,    ///< classical BB-PD, one δ everywhere, micromodulus 2C(δ)
  ClassicalVariable,  ///< classical BB-PD with each particle's own δ_i and no dual: ghost forces
};
enum class PartialVolume { None, Linear };
enum class PlaneMode { Stress, Strain };

std::string_view to_string(ForceModel m);
std::string_view to_string(PartialVolume p);
std::string_view to_string(PlaneMode p);

/// Dimension and section of the model: thickness h in 2D, cross-section area A in 1D.
struct Section {
  int dim = 3;
  PlaneMode plane = PlaneMode::Stress;
  double thickness = 1.0;  ///< 2D only (m)
  double area = 1.0;       ///< 1D only (m²)

  /// Particle volume from its cell measure (length, area or volume).
  double volume_of_cell(double cell_measure) const {
    return dim == 1 ? cell_measure * area : (dim == 2 ? cell_measure * thickness : cell_measure);
  }
};

}  // namespace dhpd
