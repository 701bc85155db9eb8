// The explicit DH-PD time stepper: owns particles, bond rows and loads.
// Velocity-Verlet (IJNME 2016 §4); only the effects the setup declares are assembled.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/base/parallel.hpp"
#include "engine/base/timers.hpp"
#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/discretization/section.hpp"
#include "engine/distributed/force_share.hpp"
#include "engine/physics/correspondence.hpp"
#include "engine/physics/fictitious_layer.hpp"
#include "engine/physics/force_kernel.hpp"
#include "engine/physics/interactions.hpp"
#include "engine/physics/interface_consistency.hpp"
#include "engine/physics/loads.hpp"
#include "engine/physics/material_law.hpp"
#include "engine/physics/ordinary_state.hpp"
#include "engine/physics/relaxation.hpp"
#include "engine/physics/stability_guard.hpp"
#include "engine/physics/time_levels.hpp"
#include "engine/simulation_setup.hpp"
#include "geometry/crack.hpp"
#include "geometry/lattice.hpp"

namespace dhpd {

/// What an editor of the discretisation (refine/) changed, handed to Simulation::commit_edit.
/// Slots are those after the edit; the engine derives everything else from them.
struct DiscretisationChange {
  /// Slots whose particle the editor wrote (in the order their kinetic energy is summed).
  std::vector<std::int32_t> new_particles;
  /// Owners whose bond rows the editor rewrote, ascending (their damage is recomputed).
  std::vector<std::int32_t> rewritten_rows;
  /// Every particle whose bond row changed (own or dual side), ascending: their stiffness, level
  /// interface factors, stable steps and forces are derived again.
  std::vector<std::int32_t> changed_rows;
  /// successor[k] takes over the loads (a traction's body force, a prescribed velocity) of the
  /// particle that had slot predecessor[k] before the edit; a slot that is its own successor
  /// keeps its entries.
  std::vector<std::int32_t> successor, predecessor;
  std::size_t old_size = 0;  ///< particles before the edit (slots at or above it are appended)
};

/// What commit_edit derived.
struct EditOutcome {
  InterfaceCorrection interfaces;  ///< the level-interface factors solved for the changed rows
  double energy_change = 0.0;      ///< kinetic + strain energy the edit added (J)
  double shadow_change = 0.0;      ///< the same for the shadow energy (new dt and forces too)
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
  /// Builds the particles and rows. The setup's points are not kept (their hash is, as
  /// fingerprint()): pass it with std::move where the caller needs it no more.
  explicit Simulation(SimulationSetup setup);

  /// What a step may compute on the way, for the outputs that follow it.
  struct StepExtras {
    /// The strain energy of the state the step leaves, from its force pass (energies() then
    /// needs no pass over the bonds; the same bits either way).
    bool strain_energy = false;
    /// Work of the caller's that one thread does during the step's force pass (SideTask), e.g.
    /// encoding an output frame from its own copy of the fields.
    const SideTask* side_task = nullptr;
    /// Work of the caller's on the state the previous step left, shared by the step's threads
    /// (RangeTask): each range before the step changes those particles, e.g. copying the damage
    /// for a measurement that the force pass's side task takes.
    const RangeTask* before_change = nullptr;
    /// A static load step calls this after each relaxation, before bonds break (EditTask): it may
    /// edit the discretisation (a refinement event) and returns whether it did; the step then
    /// relaxes the edited state again before any bond breaks (docs/theory.md §22, refinement
    /// between relaxations).
    const EditTask* between_relaxations = nullptr;
  };
  void step(StepExtras extras);
  void step() { step(StepExtras{}); }
  void run_steps(std::int64_t n) {
    for (std::int64_t k = 0; k < n; ++k) step();
  }

  /// A static run (SimulationSetup::statics): step() solves the next load step.
  bool is_static() const { return setup_.statics.has_value(); }
  /// The fraction of the loads applied: k / load_steps after static load step k (inside a load
  /// step, the one it solves); 1 in dynamics.
  double load_factor() const;
  /// Inside a static load step (between its relaxations): load_factor() is the one it solves.
  bool solving_load_step() const { return solving_load_step_; }
  /// What the last static load step did.
  const RelaxationReport& last_relaxation() const { return relaxation_report_; }
  /// The fictitious boundary layers (docs/theory.md §23), bound to slots.
  const std::vector<ResolvedLayer>& fictitious_layers() const { return layers_; }
  /// The force layer k puts on the body: −Σ V f over its particles, N.
  Vec3 layer_reaction(std::size_t k) const;
  /// The force the body beyond the plane X_axis = at puts on the body before it (the sectional
  /// force of a cut; tension positive along +axis): Σ V (f − b) over the particles with X_axis <
  /// at, exact for every model since each pair's forces are equal and opposite (docs/theory.md
  /// §22). Fictitious layers' particles count as body (their pairs are internal forces too).
  Vec3 force_across(int axis, double at) const;

  /// Multi-rate stepping is allowed: time.multirate is not false and the model is conservative.
  bool multirate_enabled() const;
  /// The time levels of multi-rate stepping (docs/theory.md §19), or null while one global step
  /// rules (multi-rate off, or every particle at level 0). dt() is then dt₀.
  const TimeLevels* time_levels() const { return levels_ ? &*levels_ : nullptr; }
  /// Particles at each time level (every particle at level 0 under one global step).
  std::vector<std::int64_t> particles_per_level() const;
  /// After an edit of the discretisation (a refinement event), at a dt₀ boundary: the time levels
  /// chosen again and the particles renumbered by level (a compaction) where multi-rate stepping
  /// is on; nothing otherwise.
  void relevel();

  /// The stretch watch (docs/theory.md §13.1): from the next step on, the steps' force passes flag
  /// each row with an own bond, intact after the pass's breaks, whose squared stretch ratio reached
  /// limit_ratio2[i] (one per particle). `key` names the rule the limits come from (a watcher
  /// reads only hits of its own rule). Any change of the discretisation (an edit, a renumbering)
  /// or a loaded state drops it.
  void watch_stretch(std::vector<double> limit_ratio2, std::uint64_t key);
  bool watching_stretch(std::uint64_t key) const {
    return !watch_.limit.empty() && watch_.key == key;
  }
  /// Per particle, 1 where the last step's force passes saw such a bond under the limits of
  /// `key`; null when they are not of the current state (no step since the watch was set or the
  /// state loaded), of another key, or the passes do not watch (fracture off, statics, the
  /// state-based families, a distributed run).
  const std::vector<std::uint8_t>* stretch_watch_hits(std::uint64_t key) const {
    return watch_.current && watch_.key == key ? &watch_.hit : nullptr;
  }

  /// Energies and momentum of the current state (deterministic sums).
  Energies energies();
  /// Whether energies() takes the strain energy from the last step's force pass (that step asked
  /// for it, and nothing edited the discretisation since).
  bool strain_energy_from_step() const {
    const auto& f = fused_energy_;
    return f.step == steps_ && f.generation == generation_ && f.layout == layout_version_;
  }
  /// Throws InstabilityError when the state holds a NaN/Inf or kinetic + strain energy is above
  /// the energy budget (step() checks the kinetic energy alone every step).
  void check_stable(const Energies& e) const;
  const EnergyBudget& energy_budget() const { return budget_; }

  /// The edit seam (refine/ uses it; docs/design.md): begin_edit records the energy of the rows
  /// an edit may change (strain energy of `energy_rows`, kinetic energy of `moving`); the editor
  /// then rewrites the store and the bond rows (replace_own_bonds), calls particles_written for
  /// particles it wrote (bond constants, row arenas), and commit_edit(change) derives the
  /// stiffness, level-interface factors, stable steps and time step, loads, forces, damage and the
  /// energy ledger of the changed rows, and counts one more generation.
  struct Discretisation {
    ParticleStore& particles;
    BondRows& bonds;
  };
  Discretisation begin_edit(std::vector<std::int32_t> energy_rows,
                            const std::vector<std::int32_t>& moving);
  void particles_written(const std::vector<std::int32_t>& slots);
  EditOutcome commit_edit(const DiscretisationChange& change, std::int64_t broken_bonds_change);
  /// The first of `n` new particle ids (ids are never reused).
  std::int32_t take_ids(std::size_t n);
  /// Renumbers the store in Morton order and compacts the bond rows (bonds keep their states);
  /// the layout version changes. Returns the seconds it took.
  double compact();
  /// Changes whenever slots are renumbered (compact): anything indexed by slot must be rebuilt.
  std::int64_t layout_version() const { return layout_version_; }
  /// The slots the last regrouping by time level moved (docs/theory.md §19.3): slot moved[t] now
  /// holds the particle that was at source[t], and `layout` is the layout_version it produced, so
  /// that a structure indexed by slot at layout − 1 can follow instead of being rebuilt.
  struct SlotMoves {
    std::int64_t layout = -1;
    std::vector<std::int32_t> moved, source;
  };
  const SlotMoves& last_slot_moves() const { return slot_moves_; }
  /// Particles appended by edits since the last compaction (or the start).
  std::size_t appended_since_compaction() const { return appended_since_compaction_; }
  /// Number of edits committed so far (0 for the scene's particles).
  std::int64_t generation() const { return generation_; }
  /// Upper bounds used by bond searches: of every horizon, and of the radius added to it.
  double max_horizon() const { return max_horizon_; }
  double bond_reach() const { return reach_; }
  /// The ordinary state-based model (null for the other families).
  const OrdinaryState* ordinary_state() const { return state_ ? &*state_ : nullptr; }
  /// Whether a state-based family (ordinary or correspondence) computes the forces.
  bool state_based() const { return state_ || correspondence_; }
  /// Whether level-interface factors are solved (dual-horizon with the correction on).
  bool corrects_interfaces() const;
  const ResolvedLoads& loads() const { return loads_; }

  /// Bytes the simulation holds, by part (capacities of its arrays: what the allocator gave).
  struct MemoryUse {
    std::size_t particles = 0, bonds = 0, other = 0;
    std::size_t total() const { return particles + bonds + other; }
  };
  MemoryUse memory_use() const;

  /// The particles; with fracture on, their damage is always that of the current bonds (§8).
  const ParticleStore& particles() const { return p_; }
  ParticleStore& particles() { return p_; }
  /// The bond rows: every bond, own and dual, with its state (engine/discretization/bonds.hpp).
  const BondRows& bonds() const { return bonds_; }
  /// What the stiffness and break tests read (valid while the simulation lives).
  BondConstants bond_constants() const;
  const std::vector<double>& micromodulus() const { return C_; }
  const std::vector<double>& critical_stretch() const { return s0_; }
  /// Multi-horizon α of each particle's interaction horizons, at 2i (toward −x) and 2i + 1
  /// (toward +x): the ordinary state-based model's own when it runs, else the bond-based one;
  /// empty under the other models (docs/theory.md §24).
  const std::vector<double>& interaction_scale() const {
    return state_ && setup_.model == ForceModel::MultiHorizon ? state_->interaction_scale()
                                                              : interaction_scale_;
  }
  /// The setup the run was built from, without its points (released once the particles hold
  /// them; fingerprint() is their hash).
  const SimulationSetup& setup() const { return setup_; }
  /// setup_fingerprint of the setup as it was given (points included).
  std::uint64_t fingerprint() const { return fingerprint_; }
  /// What the interface correction did when the simulation was built.
  const InterfaceCorrection& initial_interfaces() const { return initial_interfaces_; }
  const PhaseTimers& timers() const { return timers_; }
  PhaseTimers& timers() { return timers_; }

  double time() const { return time_; }
  double dt() const { return dt_; }
  double critical_dt() const { return critical_dt_; }
  /// The largest dt the run may take: critical_dt(), or with time levels the stable step of the
  /// coarsest particles (dt is then dt₀).
  double dt_limit() const { return levels_ ? levels_->coarse_dt : critical_dt_; }
  /// The caller (scene builder) refuses a fixed dt above dt_limit() with the scene location.
  bool dt_is_stable() const { return dt_ <= dt_limit() * (levels_ ? 1.0 + 1e-12 : 1.0); }
  std::int64_t steps_done() const { return steps_; }
  std::int64_t broken_bonds() const { return broken_; }
  /// Directed bonds evaluated so far (own bonds summed over the steps): the benchmark's unit.
  std::int64_t bond_updates() const { return bond_updates_; }
  /// Multi-rate stepping in this process (docs/theory.md §19): directed bonds evaluated at each
  /// level, and what one global step at each dt₀ step's finest level would have evaluated.
  struct LevelCounts {
    std::vector<std::int64_t> evaluated;
    std::int64_t one_step = 0;
  };
  const LevelCounts& level_counts() const { return level_counts_; }

  /// Distributed run (docs/theory.md §25): every rank holds this whole simulation (built from the
  /// same setup) and steps every particle; Zoltan gives each rank the rows whose force pass it
  /// computes, and the results are shared after each pass. Collective; throws InputError for what
  /// does not run on several ranks yet (refinement, multi-rate stepping, statics, fictitious
  /// layers, the state-based families), naming the scene key.
  void distribute(
      std::shared_ptr<const distributed::Communicator> comm, distributed::PartitionMethod method,
      distributed::RepartitionPolicy policy = distributed::RepartitionPolicy::Imbalance);
  /// The decomposition (null for a run on one rank).
  const distributed::ForceShare* force_share() const { return share_.get(); }
  /// Whether this process writes the run's outputs (rank 0, or the only process).
  bool leads() const { return !share_ || share_->comm().root(); }
  /// Ranks other than 0: do what rank 0 announces (steps, sharing bond states, `edit`) until it
  /// releases them. An InstabilityError of a step is rank 0's to report: it is met there too, and
  /// this rank keeps serving until released; so is a StoppedByRankZero of an edit or a step.
  /// `between_relaxations`: this rank's part of a static load step's refinement checks (every
  /// rank checks on its copy at the same point of the step).
  void serve(const std::function<void()>& edit = {}, const EditTask* between_relaxations = nullptr);
  /// Rank 0, before an edit that every rank makes the same way (a refinement check: the other
  /// ranks run their `edit` of serve): the bond states are shared, then the edit announced.
  void announce_edit();
  /// Rank 0's `verdict` on every rank (collective in a distributed run; `verdict` itself on one
  /// process): a decision only rank 0 can make (its memory budget) taken by every rank alike.
  bool agree(bool verdict) const;
  /// Rank 0: the other ranks' serve() returns (the first call; later ones do nothing).
  void release_ranks();
  /// Every row's bond states from the rank that owns the row (rank 0 announces it), for what
  /// reads the bond states of every row (checkpoints, the guard's copy, the strain energy from
  /// the rows); nothing when they are current or the run is not distributed.
  void share_bond_states();

 private:
  friend struct CheckpointAccess;  ///< engine/checkpoint.cpp: archives every member below
  void init_particles();
  /// compact() without its energy ledger: renumbers (by time level, then Morton order), rebuilds
  /// the rows and plans the levels.
  void renumber();
  /// Puts the particles in the blocks of `level` (per slot) by moving as few as possible
  /// (fewest_moves_by_level): rows renumbered in place, the moved and re-sorted rows' sums derived
  /// again, the levels planned (docs/theory.md §19.3).
  void regroup_by_level(const std::vector<std::int8_t>& level);
  /// What renumber and regroup_by_level renumber alike: per-particle data outside the store and
  /// the rows (interaction scales, loads, scratch flags, the ranks' owners).
  void renumber_per_particle(const std::vector<std::int32_t>& order,
                             const std::vector<std::int32_t>& new_index);
  void update_bond_constants();
  void update_bond_constants(const std::vector<std::int32_t>& slots);
  /// The ordinary state-based constants of the current rows (family OrdinaryState only).
  void build_state_model();
  /// Positions (3 per slot), work weights and ids of the particles, for the partitioner.
  struct PartitionInput {
    std::vector<double> xyz, weight;
    std::vector<std::int32_t> id;
  };
  PartitionInput partition_input() const;
  /// The force pass of this rank's rows, then every rank gets their results (§25.1).
  void distributed_forces(bool with_fracture, std::vector<double>* row_energy,
                          const SideTask* side);
  /// The same for the ordinary state-based family: this rank's breaks and dilatations, every
  /// rank gets θ, α, β (and damage), then this rank's forces, and every rank gets them.
  void distributed_state_forces(bool with_fracture);
  /// The same for the correspondence family (elastic): F and σK⁻¹ are shared between its passes.
  void distributed_correspondence_forces();
  /// What the ordinary state-based constants are built from (any family: the correspondence
  /// model takes the same).
  OrdinaryStateInputs state_inputs() const;
  /// The level-interface factors of the rows in `region` (every row when empty): the pair
  /// stiffness factors of §14 (bond-based) or the state-based weights' of §20.6.
  /// The ordinary state-based family's model of the corrected rows goes to `built` when given.
  InterfaceCorrection correct_interfaces(const std::vector<std::int32_t>& region,
                                         std::optional<OrdinaryState>* built = nullptr);
  /// Internal force densities plus body forces; with fracture, bonds break in the same pass.
  /// With `row_energy`, the pass also leaves each row's energy sum there (force kernels, Energy).
  void compute_forces(bool with_fracture = false, std::vector<double>* row_energy = nullptr,
                      const SideTask* side = nullptr);
  void enforce_prescribed_velocity();
  /// Binds the setup's layers to slots, holds their particles (loads_) and keeps their bonds.
  void resolve_layers();
  /// Every layer's displacements from the body's (at the current load factor); returns whether
  /// there is any.
  bool apply_layers();
  double boundary_power() const;
  /// The held components' reactions −V f and displacements, to integrate their work over a step
  /// (prescribed entries from `first` on).
  struct HeldState {
    std::size_t first = 0;
    std::vector<double> reaction, displacement;
  };
  HeldState held_state(std::size_t first) const;
  /// Σ ½ m v² of the prescribed velocities of the held components.
  double held_kinetic_energy() const;
  struct WorkBaseline {
    std::vector<double> loaded;  ///< displacements of the body forces' entries
    HeldState held;
  };
  /// ½ (R_before + R_now) · (u_now − u_before) over the held components of `before`.
  double held_work(const HeldState& before) const;
  /// One static load step (simulation_static.cpp): the extras run first; returns the body
  /// forces' work.
  double static_step(const StepExtras& extras);
  /// The work of a load step so far: booked segments, and the baseline of the open one.
  struct StaticWork {
    WorkBaseline since;
    double done = 0.0;
  };
  /// Relaxes a load step's state, breaking bonds and calling `edit` between relaxations until
  /// nothing breaks and nothing is edited (simulation_static.cpp).
  void relax_and_break(RelaxationState& state, const EditTask* edit, StaticWork& work, double mean);
  /// Calls `edit`; when it edited the discretisation, books the work up to it and prepares the
  /// edited state (prescribed displacements, forces, a new work baseline). Returns whether.
  bool edit_between_relaxations(const EditTask& edit, StaticWork& work, double mean);
  /// Relaxes the current load to `tolerance` of it, or of `floor` when that is larger (one
  /// round); returns the iterations.
  std::int64_t relax(RelaxationState& state, double tolerance, double floor);
  /// τ_i² of adaptive dynamic relaxation for the current rows (Lanczos on D⁻¹K).
  std::vector<double> relaxation_steps() const;
  /// τ² and the held axes of the current rows and loads.
  void prepare_relaxation(RelaxationState& state) const;
  /// Where the loaded and held components are, to integrate the work done on them since.
  struct WorkBaseline;
  WorkBaseline work_baseline() const;
  /// The body forces' work (at load factor `factor`) and the held components' since `w`.
  double work_since(const WorkBaseline& w, double factor) const;
  /// Σ |λ V b|² over the body forces at the current load factor (the applied part of the load
  /// norm; the held components' reactions are ResidualNorms::reaction2).
  double applied_load2() const;
  /// One velocity-Verlet step of every particle; returns the body forces' work.
  double verlet_step(const StepExtras& extras);
  /// One dt₀ step of the multi-rate scheme (simulation_multirate.cpp); returns the body forces'
  /// work and sets `evaluated` to the directed bonds it evaluated.
  double multirate_step(const StepExtras& extras, std::int64_t& evaluated);
  /// The end of a step: work ledger, the guard's kinetic check, clocks.
  void finish_step(double body_work);
  /// Chooses the time levels of the current slots: the plans when more than one level is needed
  /// (the slots must be sorted by level), none otherwise; `chosen`: the choice of this very state.
  void plan_levels(std::optional<LevelChoice> chosen = std::nullopt);
  /// The sub-step of level l (dt₀/2^l) and, recursively, those of the finer levels.
  void level_substep(int l, const SideTask* side);
  void level_kick(int l);
  void level_drift(int l);
  /// F_l at the current positions (with fracture when `fracture`); level 0 adds the body forces.
  void level_forces(int l, bool fracture, const SideTask* side);
  LevelChoice choose_levels() const;
  /// p.force_density = Σ_l F_l.
  void sum_level_forces();
  /// Energies::verlet_correction of the multi-rate scheme: 2 Σ_l (dt_l²/8) Σ V |F_l|²/ρ.
  double multirate_correction() const;
  /// Throws InstabilityError; a NaN `energy` reports a non-finite state.
  [[noreturn]] void stop_unstable(const char* measured, double energy, double allowed,
                                  std::int64_t step, double time) const;
  /// Δt_crit of the current rows by setup_.stable_step (particle_dt_ must be current); not below
  /// the per-particle bound. Keeps the last Lanczos estimate and the bound it was made at.
  double estimate_critical_dt();
  /// The Lanczos step of the state-based model's linearised stiffness (docs/theory.md §20.3),
  /// with the densities of `masses` (by default the particles').
  double state_lanczos_dt() const { return state_lanczos_dt(p_); }
  double state_lanczos_dt(const ParticleStore& masses) const;
  /// Energies::verlet_correction of the current state (a pass over particles, not bonds).
  double verlet_correction() const;

  SimulationSetup setup_;
  std::uint64_t fingerprint_ = 0;
  ParticleStore p_;
  BondRows bonds_;
  ResolvedLoads loads_;
  std::vector<double> C_, s0_;
  std::vector<double>
      interaction_scale_;  ///< bond-based multi-horizon α (the rows' K), 2 a particle
  /// The state-based fracture factor Φ of each material (s0 = sqrt(G0/(Φ δ)), §20.4).
  std::vector<double> state_phi_;
  /// The ordinary state-based model's constants and dilatation (family OrdinaryState only).
  std::optional<OrdinaryState> state_;
  /// The correspondence model (family Correspondence only).
  std::optional<Correspondence> correspondence_;
  std::vector<double> particle_dt_;  ///< stable step of each particle's row (docs/theory.md §9)
  double reach_ = 0.0;               ///< upper bound on radii (exact) for bond searches
  double max_horizon_ = 0.0;         ///< upper bound on every horizon
  std::size_t appended_since_compaction_ = 0;
  std::int64_t layout_version_ = 0;
  SlotMoves slot_moves_;  ///< the last regroup_by_level's (not archived)
  /// The plans an edit dropped, kept until the levels are planned again so that the rows the edit
  /// left alone keep their level forces (docs/theory.md §19.3). Valid at `generation` and
  /// `layout` only; not archived.
  struct FormerPlans {
    TimeLevels levels;
    /// Per slot: its level forces are evaluated again. A slot that a regrouping moved is among
    /// them (its row and its partners' are re-sorted), so a kept row is in its former slot.
    std::vector<std::uint8_t> recompute;
    std::int64_t generation = -1, layout = -1;
  };
  std::optional<FormerPlans> former_;
  /// The former plans when they describe the current slots (else none).
  FormerPlans* current_former();
  /// Every level's forces of the new plans; the rows whose segments and inputs are those of the
  /// former plans copy their forces from them.
  void plan_level_forces(FormerPlans* former);
  // The open edit (begin_edit .. commit_edit); not part of the state between edits.
  struct OpenEdit {
    std::vector<std::int32_t> energy_rows;
    double energy_before = 0.0, correction_before = 0.0;
  };
  std::optional<OpenEdit> edit_;
  std::vector<std::uint8_t> touched_;  ///< commit_edit scratch, all 0 between edits
  PhaseTimers timers_;
  double time_ = 0.0, dt_ = 0.0, critical_dt_ = 0.0;
  /// The last Lanczos estimate and the smallest per-particle bound when it was made (0: none).
  double lanczos_dt_ = 0.0, lanczos_bound_ = 0.0;
  double external_work_ = 0.0, last_power_ = 0.0;
  EnergyBudget budget_;
  bool conservative_ = true;              ///< the model conserves energy (not classical-variable)
  double blowup_factor_ = 2.0;            ///< plain energy above this × the balance is a blow-up
  std::vector<double> kinetic_blocks_;    ///< guard scratch
  kernel::PackedPoints kernel_points_;    ///< force kernel scratch (kernel::pack_points)
  std::optional<TimeLevels> levels_;      ///< multi-rate plans (derived from the state)
  std::int64_t level_evaluations_ = 0;    ///< directed bonds the current dt₀ step evaluated
  LevelCounts level_counts_;              ///< not archived: this process's steps
  std::vector<double> load_start_;        ///< multirate_step scratch: loaded displacements
  std::vector<std::int32_t> level_rows_;  ///< level_forces scratch: this rank's rows of a level
  /// The stretch watch (watch_stretch): limits, the hits of the last step (per level under time
  /// levels, then merged), and whether they are the current state's. Not archived.
  struct WatchState {
    std::vector<double> limit;
    std::vector<std::uint8_t> hit, level_hit;
    std::uint64_t key = 0;
    bool current = false;
  };
  WatchState watch_;
  /// The watch for a force pass writing `hits` (empty when the passes do not watch).
  kernel::StretchWatch stretch_watch_into(std::vector<std::uint8_t>& hits);
  /// The same for a pass over time level `level`'s segments (its own hits, merged after the step).
  kernel::StretchWatch level_stretch_watch(int level);
  void merge_level_watch();
  bool stretch_watched() const { return !watch_.limit.empty(); }
  /// Limits held, one per current particle (an open edit may have appended particles).
  bool watch_fits() const { return stretch_watched() && watch_.limit.size() == p_.size(); }
  void drop_stretch_watch() { watch_ = {}; }
  /// The strain energy a step's force pass computed, valid while steps_, generation_ and
  /// layout_version_ are still those it was computed at (not part of the state).
  struct FusedEnergy {
    std::int64_t step = -1, generation = -1, layout = -1;
    double strain = 0.0;
    std::vector<double> rows;  ///< the pass's row sums (scratch)
  };
  FusedEnergy fused_energy_;
  std::int64_t steps_ = 0, broken_ = 0, bond_updates_ = 0;
  std::int64_t generation_ = 0;
  bool solving_load_step_ = false;  ///< inside static_step (load_factor of the next step)
  /// The largest load (|body forces and reactions|, N) a static equilibrium has carried: the
  /// relaxation's reference never falls below it (a parted body carries almost nothing).
  double load_scale_ = 0.0;
  RelaxationReport relaxation_report_;  ///< not archived: the last load step's
  std::vector<ResolvedLayer> layers_;   ///< derived from the setup and the ids
  std::size_t first_layer_entry_ = 0;   ///< loads_.prescribed entries of layers start here
  bool has_time_functions_ = false;     ///< a prescribed component is a function of time
  std::int32_t next_id_ = 0;
  InterfaceCorrection initial_interfaces_;
  std::unique_ptr<distributed::ForceShare> share_;  ///< not archived: this launch's ranks
  bool bonds_shared_ = true;  ///< every row's bond states are current on this rank
  bool released_ = false;     ///< rank 0 has let the other ranks go
};

}  // namespace dhpd
