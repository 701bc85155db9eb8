// Choices that fix the discretisation and the force model for a whole run.
#pragma once
#include <string_view>

namespace dhpd {

enum class ForceModel {
  DualHorizon,        ///< DH-PD: own bonds with C(δ_i) plus dual reactions (IJNME 2016 eq. 27)
  ConstantHorizon,    ///< classical BB-PD, one δ everywhere, micromodulus 2C(δ)
  ClassicalVariable,  ///< classical BB-PD with each particle's own δ_i and no dual: ghost forces
  /// Multi-horizon PD (CMES 2019 §2; docs/theory.md §24): classical BB-PD whose finer particles
  /// also integrate over the coarser particles that include them (interaction horizons), the
  /// pair integrand scaled by α from eq. 7; 1D.
  MultiHorizon,
};

/// Whether every pair's forces are equal and opposite (momentum exact, a stiffness symmetric in
/// the mass inner product): dual and constant horizons; not the classical variable-horizon and
/// multi-horizon models.
inline bool conserves_momentum(ForceModel m) {
  return m == ForceModel::DualHorizon || m == ForceModel::ConstantHorizon;
}
/// The force state of a bond (docs/theory.md §20, §21): bond-based (a pair force from the bond's
/// own stretch), ordinary state-based (also the owner's dilatation; any Poisson's ratio) or
/// correspondence (the owner's deformation gradient and Hooke's stress).
enum class ModelFamily { Bond, OrdinaryState, Correspondence };
/// Influence function ω of the state-based models: 1, or δ_owner/|ξ| (the Madenci–Oterkus form's).
enum class Influence { Constant, InverseDistance };
/// β_ij rule of docs/theory.md §7: none, linear (CMAME 2017 eq. A.1), exact (App. A, ball overlap).
enum class PartialVolume { None, Linear, Exact };
enum class PlaneMode { Stress, Strain };

std::string_view to_string(ForceModel m);
std::string_view to_string(ModelFamily f);
std::string_view to_string(Influence w);
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
  /// Cell measure (length, area or volume) of a particle of volume V.
  double cell_of_volume(double volume) const {
    return dim == 1 ? volume / area : (dim == 2 ? volume / thickness : volume);
  }
  /// Radius of the interval, disk or ball with the particle's cell measure (docs/theory.md §7):
  /// V/(2A) in 1D (Δx/2 on a lattice), sqrt(A_cell/π) in 2D, (3V/(4π))^(1/3) in 3D.
  double equal_measure_radius(double volume) const;
  /// Volume of a full horizon of radius δ: 2δA in 1D, πδ²h in 2D, 4/3 πδ³ in 3D.
  double horizon_volume(double delta) const;
};

}  // namespace dhpd
