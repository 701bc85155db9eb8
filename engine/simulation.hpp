// The explicit DH-PD time stepper: owns particles, bonds, interaction rows and loads.
// Velocity-Verlet (IJNME 2016 §4); only the effects the setup declares are assembled.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/bonds.hpp"
#include "engine/interactions.hpp"
#include "engine/interface_consistency.hpp"
#include "engine/loads.hpp"
#include "engine/material_law.hpp"
#include "engine/particles.hpp"
#include "engine/refinement_event.hpp"
#include "engine/settings.hpp"
#include "engine/spatial_grid.hpp"
#include "engine/stability_guard.hpp"
#include "engine/timers.hpp"
#include "geometry/crack.hpp"
#include "geometry/lattice.hpp"

namespace dhpd {

struct Effects {
  bool fracture = false;
  bool refinement = false;  ///< prepare the incremental search structure at start
};

/// Everything a run needs, already validated and in SI units.
struct SimulationSetup {
  Section section;
  ForceModel model = ForceModel::DualHorizon;
  PartialVolume partial_volume = PartialVolume::None;
  double horizon_factor = 3.015;
  std::vector<Material> materials;
  geometry::PointSet points;  ///< positions, cell measures, spacings, material indices
  std::vector<geometry::Crack> cracks;
  std::vector<geometry::Shape> no_fail;
  std::vector<InitialCondition> initial_conditions;
  std::vector<BoundaryCondition> boundary_conditions;
  Effects effects;
  double safety = 0.8;
  std::optional<double> fixed_dt;
  bool spatial_sort = true;  ///< Morton-order the particles (ids keep the generation order)
  /// The body's shape, when known: children outside it are not created.
  std::optional<geometry::Shape> body;
  /// Refinement appends children after the particles of the scene; once appended particles exceed
  /// this fraction of all (or garbage exceeds half the bond arena) the store is re-sorted in
  /// Morton order and every row array compacted. 0 never re-sorts.
  double resort_fraction = 0.2;
  /// The instability guard stops a run whose kinetic + strain energy exceeds initial + external
  /// work + refinement mapping by more than this fraction of their scale (EnergyBudget).
  double energy_tolerance = 0.01;
  /// Stiffness factors on the bonds near horizon jumps so that a homogeneous deformation puts no
  /// force there (interface_consistency.hpp; dual-horizon only). Off: the papers' DH-PD, whose
  /// level interfaces carry a force layer 0.5–0.8 times a free surface's (docs/theory.md §4).
  bool interface_correction = true;
};

/// What one refinement event did (Simulation::apply_refinement).
struct RefinementEvent {
  std::int64_t generation = 0;  ///< the generation the event created
  std::size_t parents = 0, children = 0;
  std::size_t dropped = 0;          ///< children not created (outside the body)
  std::size_t rows_rebuilt = 0;     ///< owners whose bond rows were rebuilt
  std::size_t bonds_rebuilt = 0;    ///< bonds written by the event
  std::size_t rows_touched = 0;     ///< interaction rows rewritten (owners and their neighbours)
  std::size_t bonds = 0;            ///< bonds after the event
  std::int64_t started_broken = 0;  ///< new bonds set broken by the no-healing rule
  /// New bonds set broken because the mapped state stretched them to s0 (starts_overstretched).
  std::int64_t started_overstretched = 0;
  InterfaceCorrection interfaces;  ///< the stiffness factors the event solved for
  std::size_t reduced_fits = 0;    ///< parents whose mapping gradient had a reduced rank
  double seconds = 0.0;            ///< the event itself (split and incremental rebuild)
  bool resorted = false;           ///< the store was re-sorted and compacted after the event
  double resort_seconds = 0.0;     ///< cost of that re-sort (not in `seconds`)
  double energy_change = 0.0;      ///< kinetic + strain energy the state mapping added (J)
  double shadow_change = 0.0;      ///< the same for the shadow energy (new dt and forces too)
  /// Per child: its slot and its parent's slot before the event (slots as after the event,
  /// before any re-sort). The test of incremental = from scratch uses them.
  std::vector<std::int32_t> child_slot, parent_slot;
};

struct Energies {
  double kinetic = 0.0;
  double strain = 0.0;
  double external_work = 0.0;
  Vec3 momentum{0, 0, 0};
  /// (dt²/8) Σ V |f|²/ρ over free components: the plain kinetic energy minus velocity Verlet's
  /// shadow one, ½ m v_{n−½}·v_{n+½}, which (with the strain energy) a stable linear run conserves.
  double verlet_correction = 0.0;
};

class Simulation {
 public:
  explicit Simulation(const SimulationSetup& setup);

  void step();
  void run_steps(std::int64_t n) {
    for (std::int64_t k = 0; k < n; ++k) step();
  }

  /// Energies and momentum of the current state (deterministic sums).
  Energies energies();
  /// Throws InstabilityError when the state holds a NaN/Inf or kinetic + strain energy is above
  /// the energy budget (step() checks the kinetic energy alone every step).
  void check_stable(const Energies& e) const;
  const EnergyBudget& energy_budget() const { return budget_; }
  /// Recomputes p.damage (only meaningful with fracture on).
  void update_damage();

  /// Splits the given particles (indices of the current generation) into up to 2^dim children each
  /// (plan_split; u and v by `mapping`) and rebuilds incrementally: only the children and the
  /// owners of bonds on the parents or within reach of a child get new bond rows; the dual rows
  /// and interaction rows of their neighbours are patched; the no-healing rule sets the new bonds;
  /// loads, no_fail, stable step, forces and damage are updated for the touched particles. A
  /// parent's first child takes its slot, the other children are appended, so every other index
  /// stays valid, unless the event ends with a re-sort (RefinementEvent::resorted). Refused for
  /// constant-horizon (one δ for the whole body).
  RefinementEvent apply_refinement(const std::vector<std::int32_t>& parents,
                                   StateMapping mapping = StateMapping::Linear);
  /// Re-sorts the store in Morton order and compacts every row array (bonds keep their states).
  /// Returns the seconds it took.
  double resort();
  /// Number of refinement events applied so far (0 for the scene's particles).
  std::int64_t generation() const { return generation_; }

  const ParticleStore& particles() const { return p_; }
  ParticleStore& particles() { return p_; }
  const BondList& bonds() const { return bonds_; }
  const DualList& dual() const { return dual_; }
  const InteractionList& interactions() const { return il_; }
  const std::vector<double>& micromodulus() const { return C_; }
  const std::vector<double>& critical_stretch() const { return s0_; }
  const SimulationSetup& setup() const { return setup_; }
  /// What the interface correction did when the simulation was built.
  const InterfaceCorrection& initial_interfaces() const { return initial_interfaces_; }
  const PhaseTimers& timers() const { return timers_; }
  PhaseTimers& timers() { return timers_; }

  double time() const { return time_; }
  double dt() const { return dt_; }
  double critical_dt() const { return critical_dt_; }
  /// The caller (scene builder) refuses a fixed dt above critical_dt() with the scene location.
  bool dt_is_stable() const { return dt_ <= critical_dt_; }
  std::int64_t steps_done() const { return steps_; }
  std::int64_t broken_bonds() const { return broken_; }
  std::int64_t interaction_updates() const { return interaction_updates_; }

 private:
  friend struct CheckpointAccess;  ///< engine/checkpoint.cpp: archives every member below
  void init_particles();
  void update_bond_constants();
  void update_bond_constants(const std::vector<std::int32_t>& slots);
  void compute_forces();
  // Refinement (simulation_refine.cpp, simulation_rows.cpp).
  struct EventScratch;
  void ensure_grid();
  std::vector<std::int32_t> old_neighbourhood(const SplitPlan& plan) const;
  std::vector<std::int32_t> owners_to_rebuild(const SplitPlan& plan) const;
  void rebuild_rows(EventScratch& ev, RefinementEvent& out);
  void finish_event(EventScratch& ev, RefinementEvent& out);
  bool corrects_interfaces() const;
  void enforce_prescribed_velocity();
  double boundary_power() const;
  /// Throws InstabilityError; a NaN `energy` reports a non-finite state.
  [[noreturn]] void stop_unstable(const char* measured, double energy, double allowed,
                                  std::int64_t step, double time) const;
  std::vector<std::int32_t> event_energy_rows(const SplitPlan& plan) const;
  /// Energies::verlet_correction of the current state (a pass over particles, not bonds).
  double verlet_correction() const;

  SimulationSetup setup_;
  ParticleStore p_;
  BondList bonds_;
  DualList dual_;
  InteractionList il_;
  ResolvedLoads loads_;
  std::vector<double> C_, s0_;
  std::vector<double> particle_dt_;  ///< stable step of each particle's row (dhpd.md §5)
  std::optional<SpatialGrid> grid_;  ///< incremental search (built at the first event)
  double reach_ = 0.0;               ///< upper bound on radii (exact) for bond searches
  double max_horizon_ = 0.0;         ///< upper bound on every horizon
  std::size_t appended_since_sort_ = 0;
  std::vector<std::int32_t> parent_slot_, child_of_slot_;  ///< event scratch, −1 outside events
  std::vector<std::uint8_t> touched_;                      ///< event scratch, 0 outside events
  PhaseTimers timers_;
  double time_ = 0.0, dt_ = 0.0, critical_dt_ = 0.0;
  double external_work_ = 0.0, last_power_ = 0.0;
  EnergyBudget budget_;
  bool conservative_ = true;            ///< the model conserves energy (not classical-variable)
  double blowup_factor_ = 2.0;          ///< plain energy above this × the balance is a blow-up
  std::vector<double> kinetic_blocks_;  ///< guard scratch
  std::int64_t steps_ = 0, broken_ = 0, interaction_updates_ = 0;
  std::int64_t generation_ = 0;
  std::int32_t next_id_ = 0;
  InterfaceCorrection initial_interfaces_;
};

}  // namespace dhpd
