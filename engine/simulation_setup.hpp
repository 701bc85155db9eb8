// What a Simulation is built from (engine/simulation.hpp): the validated setup of a run, in SI
// units, and the effects it declares.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/section.hpp"
#include "engine/physics/fictitious_layer.hpp"
#include "engine/physics/loads.hpp"
#include "engine/physics/material_law.hpp"
#include "engine/physics/relaxation.hpp"
#include "geometry/crack.hpp"
#include "geometry/lattice.hpp"
#include "geometry/shapes.hpp"

namespace dhpd {

struct Effects {
  bool fracture = false;
  bool refinement = false;  ///< refine/ edits the discretisation during the run
};

/// How the run's stable step Δt_crit is found (docs/theory.md §9).
enum class StableStepEstimate {
  /// 2/ω_max of the linearised bond stiffness by Lanczos iteration (9.3): the tight step.
  Lanczos,
  /// The per-particle bound (9.1): always safe, 0.46–0.84 of the tight step (the default until
  /// the paper cases are validated at the tight step, docs/theory.md §9).
  ParticleBound,
};

/// Everything a run needs, already validated and in SI units.
struct SimulationSetup {
  Section section;
  ForceModel model = ForceModel::DualHorizon;
  /// Bond-based or ordinary state-based (docs/theory.md §20); the state-based family takes one
  /// global step and no refinement (yet).
  ModelFamily family = ModelFamily::Bond;
  Influence influence = Influence::Constant;  ///< ω of the state-based family
  /// The state-based family's surface correction (docs/theory.md §20.5).
  bool surface_correction = true;
  PartialVolume partial_volume = PartialVolume::None;
  double horizon_factor = 3.015;
  std::vector<Material> materials;
  geometry::PointSet points;  ///< positions, cell measures, spacings, material indices
  std::vector<geometry::Crack> cracks;
  std::vector<geometry::Shape> no_fail;
  std::vector<InitialCondition> initial_conditions;
  std::vector<BoundaryCondition> boundary_conditions;
  Effects effects;
  double safety = 0.5;
  std::optional<double> fixed_dt;
  StableStepEstimate stable_step = StableStepEstimate::Lanczos;
  /// Multi-rate stepping (docs/theory.md §19): particles step at dt₀/2^ℓ by their time level.
  /// true: on wherever the particles need more than one level; false: one global step; nullopt
  /// (the default): levels where they evaluate fewer bonds than one global step by more than
  /// kLevelOverhead, else one global step (docs/theory.md §19.5).
  std::optional<bool> multirate;
  /// The most time levels a run may use (a particle that needs more is refused).
  int max_time_levels = 8;
  bool spatial_sort = true;  ///< Morton-order the particles (ids keep the generation order)
  /// The body's shape, when known: refinement creates no particle outside it.
  std::optional<geometry::Shape> body;
  /// Edits append particles after those of the scene; once appended particles exceed
  /// this fraction of all (or garbage exceeds half the bond arena) the store is re-sorted in
  /// Morton order and every row array compacted. 0 never re-sorts.
  double resort_fraction = 0.2;
  /// The instability guard stops a run whose kinetic + strain energy exceeds initial + external
  /// work + refinement mapping by more than this fraction of their scale (EnergyBudget).
  double energy_tolerance = 0.01;
  /// Stiffness factors on the bonds near horizon jumps so that a homogeneous deformation puts no
  /// force there (interface_consistency.hpp; dual-horizon only). Off: the papers' DH-PD, whose
  /// level interfaces carry a force layer 0.5–0.8 times a free surface's (docs/theory.md §14).
  bool interface_correction = true;
  /// Statics (docs/theory.md §22): each step() is a load step solved by adaptive dynamic
  /// relaxation, at load factor k / load_steps; absent: explicit dynamics.
  std::optional<StaticSolver> statics;
  std::int64_t load_steps = 1;  ///< statics: steps to the full load
  /// Fictitious boundary layers (docs/theory.md §23); their particles are in `points`.
  std::vector<FictitiousLayerSpec> layers;
};

}  // namespace dhpd
