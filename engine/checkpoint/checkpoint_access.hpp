// The one list of a Simulation's members that checkpoints and the guard's copy archive
// (docs/checkpoint.md): the whole state (save, load) and the part a time step changes (save_step,
// load_step). Included only by engine/checkpoint/*.cpp.
#pragma once
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <string>
#include <type_traits>

#include "engine/checkpoint/archive.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

/// Every member of a Simulation that decides its future, in one list for writing and reading.
struct CheckpointAccess {
  /// Loads and per-particle constants: they change only when the discretisation does.
  template <class Sim, class Ar>
  static void loads_and_constants(Sim& s, Ar& ar) {
    auto& l = s.loads_;
    ar(l.prescribed), ar(l.mask), ar(l.prescribed_velocity), ar(l.prescribed_displacement);
    ar(l.condition);
    ar(l.loaded), ar(l.body_force);
    ar(l.condition_body_force);
    ar(s.C_), ar(s.s0_), ar(s.particle_dt_);
    ar(s.reach_), ar(s.max_horizon_), ar(s.appended_since_compaction_), ar(s.layout_version_);
    ar(s.lanczos_dt_), ar(s.lanczos_bound_);
  }

  /// Clocks, ledgers and counters: the last members of both lists.
  template <class Sim, class Ar>
  static void clocks(Sim& s, Ar& ar) {
    ar(s.time_), ar(s.dt_), ar(s.critical_dt_);
    ar(s.external_work_), ar(s.last_power_), ar(s.load_scale_);
    ar(s.budget_.tolerance), ar(s.budget_.initial), ar(s.budget_.mapping), ar(s.budget_.scale);
    ar(s.conservative_), ar(s.blowup_factor_);
    ar(s.steps_), ar(s.broken_), ar(s.bond_updates_), ar(s.generation_), ar(s.next_id_);
  }

  /// The bond rows as a checkpoint holds them: what cannot be derived from the particles (each
  /// row's entry count, then the entries' flags and, where level interfaces were corrected, the
  /// own bonds' factors, in row order, and the stiffness scale). The rows themselves (neighbours,
  /// lengths, stiffness, break thresholds) are built again from the particles on loading: a build
  /// from scratch gives every row the entries an incremental run gave it (test
  /// RefinementIncremental), so the state is the same whatever the arena's layout was.
  struct SavedRows {
    std::vector<std::int32_t> count;
    std::vector<std::uint8_t> flags;
    std::vector<float> factor, dilatation_factor;
    double stiffness_scale = 1.0;
  };

  static SavedRows saved_rows(const BondRows& b) {
    SavedRows r;
    r.stiffness_scale = b.stiffness_scale;
    r.count.resize(b.particles());
    r.flags.reserve(static_cast<std::size_t>(b.live));
    if (!b.factor.empty()) r.factor.reserve(static_cast<std::size_t>(b.live));
    if (!b.dilatation_factor.empty()) r.dilatation_factor.reserve(static_cast<std::size_t>(b.live));
    for (std::size_t i = 0; i < b.particles(); ++i) {  // each row's entries as one block
      r.count[i] = b.rows.count[i];
      r.flags.insert(r.flags.end(), b.flags.begin() + b.begin(i), b.flags.begin() + b.end(i));
      if (!b.factor.empty())
        r.factor.insert(r.factor.end(), b.factor.begin() + b.begin(i), b.factor.begin() + b.end(i));
      if (!b.dilatation_factor.empty())
        r.dilatation_factor.insert(r.dilatation_factor.end(),
                                   b.dilatation_factor.begin() + b.begin(i),
                                   b.dilatation_factor.begin() + b.end(i));
    }
    return r;
  }

  template <class Ar>
  static void rows_part(SavedRows& r, Ar& ar) {
    ar(r.count), ar(r.flags), ar(r.factor), ar(r.dilatation_factor), ar(r.stiffness_scale);
  }

  /// The rows built from the loaded particles, with the saved flags and factors; refuses a
  /// checkpoint whose rows do not fit them.
  static void restore_rows(Simulation& s, const SavedRows& r, const archive::Reader& ar) {
    const auto& p = s.p_;
    if (r.count.size() != p.size() || r.stiffness_scale <= 0.0)
      ar.fail("its bond rows do not fit its particles");
    BondRows b = build_bond_rows(p, s.setup_.partial_volume, s.setup_.cracks);
    if (b.rows.count != r.count || r.flags.size() != b.other.size() ||
        !(r.factor.empty() || r.factor.size() == b.other.size()) ||
        !(r.dilatation_factor.empty() || r.dilatation_factor.size() == b.other.size()))
      ar.fail("its bond rows are not those its particles give (another scene or version?)");
    for (std::size_t k = 0; k < r.flags.size(); ++k) {
      const auto f = r.flags[k];
      const bool own = b.flags[k] & kOwn, dual = b.flags[k] & kDual;
      if ((f & kOwn) != (own ? kOwn : 0) || (f & kDual) != (dual ? kDual : 0) || f > 15)
        ar.fail("its bond rows are not those its particles give (another scene or version?)");
    }
    b.flags = r.flags;
    b.factor = r.factor;
    b.dilatation_factor = r.dilatation_factor;
    b.stiffness_scale = r.stiffness_scale;
    s.bonds_ = std::move(b);
    refresh_rows(s.bonds_, s.bond_constants(), false);
  }

  /// What a time step changes between edits (the guard's copy): the bonds' intact states (the
  /// rows' flags), clocks, ledgers and counters, with every state field of the particles
  /// (save_step). The stiffness follows from the flags and is recomputed on loading; the rest of
  /// the rows, the loads and the per-particle constants change only in an edit.
  template <class Sim, class Ar>
  static void step_members(Sim& s, Ar& ar) {
    ar(s.bonds_.flags);
    clocks(s, ar);
  }

  /// The particle fields, or with `state_only` those of FieldGroup::State (a time step changes
  /// nothing else; geometry changes only in an edit).
  template <class Ar>
  static void save_fields(const Simulation& s, Ar& ar, bool state_only = false) {
    ar(static_cast<std::int32_t>(s.p_.dim()));
    // fields() hands out pointers for writing; here they are only read.
    for (const auto& f : const_cast<ParticleStore&>(s.p_).fields()) {
      if (state_only && f.group != FieldGroup::State) continue;
      ar(std::string(f.name));
      std::visit([&ar](const auto* data) { ar(*data); }, f.data);
    }
  }

  static void load_fields(Simulation& s, archive::Reader& ar, bool state_only = false) {
    s.drop_stretch_watch();  // the hits were of the positions overwritten here
    s.slot_moves_ = {};      // of the layout before: nothing indexed by slot follows them
    s.former_.reset();       // plans of the state overwritten here
    std::int32_t dim = 0;
    ar(dim);
    if (dim != s.p_.dim())
      ar.fail(fmt::format("it is a {}D run, this scene is {}D", dim, s.p_.dim()));
    for (auto& f : s.p_.fields()) {
      if (state_only && f.group != FieldGroup::State) continue;
      std::string name;
      ar(name);
      if (name != f.name)
        ar.fail(fmt::format("particle field '{}' where '{}' was expected", name, f.name));
      std::visit([&ar](auto* data) { ar(*data); }, f.data);
    }
  }

  template <class Ar>
  static void save_timers(const Simulation& s, Ar& ar) {
    std::array<double, static_cast<int>(Phase::Count)> seconds{};
    for (int k = 0; k < static_cast<int>(Phase::Count); ++k)
      seconds[k] = s.timers_.seconds(static_cast<Phase>(k));
    ar(seconds);
  }

  static void load_timers(Simulation& s, archive::Reader& ar) {
    std::array<double, static_cast<int>(Phase::Count)> seconds{};
    ar(seconds);
    s.timers_ = PhaseTimers{};
    for (int k = 0; k < static_cast<int>(Phase::Count); ++k)
      s.timers_.add(static_cast<Phase>(k), seconds[k]);
  }

  template <class Ar>
  static void save_step(const Simulation& s, Ar& ar) {
    save_fields(s, ar, true);
    step_members(s, ar);
    save_timers(s, ar);
  }

  /// Writes save(sim, writer) over `out`, in its memory when it is large enough (else `out` is
  /// released before the new buffer is taken): replacing a copy never holds two.
  template <class Save>
  static void save_into(const Simulation& sim, std::vector<std::byte>& out, Save save) {
    archive::Writer count(true);
    save(sim, count);
    if (count.size() > out.capacity()) std::vector<std::byte>().swap(out);
    archive::Writer w(std::move(out));
    w.reserve(count.size());
    save(sim, w);
    out = std::move(w.bytes());
  }

  /// Overlays a save_step of this simulation's discretisation (same bonds and rows). With
  /// `saved_start`, the step was saved from rows laid out at those starts (an arena with room
  /// between rows, as events leave it) and `s` holds the same rows packed (a whole state loaded):
  /// the flags are packed to fit.
  /// plan_levels of a state this process alone loads (rank 0 restoring the guard's copy of a
  /// distributed run: no other rank takes part, so the level forces are computed here whole).
  static void plan_levels_alone(Simulation& s) {
    auto share = std::move(s.share_);
    s.plan_levels();
    s.share_ = std::move(share);
  }

  static void load_step(Simulation& s, archive::Reader& ar,
                        const std::vector<std::int64_t>* saved_start = nullptr) {
    load_fields(s, ar, true);
    step_members(s, ar);
    load_timers(s, ar);
    if (saved_start) pack_flags(s.bonds_, *saved_start, ar);
    if (ar.remaining() != 0) ar.fail("bytes left after the step state");
    if (!particles_fit(s) || s.bonds_.rows.rows() != s.p_.size() ||
        s.bonds_.flags.size() != s.bonds_.other.size())
      ar.fail("its arrays do not fit this discretisation");
    refresh_rows(s.bonds_, s.bond_constants(), false);
    s.touched_.assign(s.p_.size(), 0);
    s.edit_.reset();
    s.fused_energy_ = {};
    s.bonds_shared_ = true;  // a saved state holds every row's bond states
    plan_levels_alone(s);    // the level forces of the restored positions
  }

  /// The flags of rows that started at `start` (each row's count as now), packed back to back.
  static void pack_flags(BondRows& b, const std::vector<std::int64_t>& start,
                         const archive::Reader& ar) {
    const auto& count = b.rows.count;
    if (start.size() != count.size()) ar.fail("its rows do not fit this discretisation");
    std::vector<std::uint8_t> packed;
    packed.reserve(b.other.size());
    for (std::size_t i = 0; i < count.size(); ++i) {
      const auto from = start[i], to = start[i] + count[i];
      if (from < 0 || to > static_cast<std::int64_t>(b.flags.size()))
        ar.fail("its rows do not fit this discretisation");
      packed.insert(packed.end(), b.flags.begin() + from, b.flags.begin() + to);
    }
    b.flags = std::move(packed);
  }

  template <class Ar>
  static void save(const Simulation& s, Ar& ar) {
    save_fields(s, ar);
    auto r = saved_rows(s.bonds_);
    rows_part(r, ar);
    loads_and_constants(s, ar);
    clocks(s, ar);
    save_timers(s, ar);
  }

  static void load(Simulation& s, archive::Reader& ar) {
    load_fields(s, ar);
    SavedRows r;
    rows_part(r, ar);
    loads_and_constants(s, ar);
    clocks(s, ar);
    if (!particles_fit(s)) ar.fail("its particle arrays do not fit together");
    restore_rows(s, r, ar);
    load_timers(s, ar);
    if (ar.remaining() != 0) ar.fail("bytes left after the simulation state");
    check_consistent(s, ar);
    s.touched_.assign(s.p_.size(), 0);
    s.edit_.reset();
    s.fused_energy_ = {};
    s.bonds_shared_ = true;
    // Damage follows from the flags (the stepper keeps it current between steps).
    if (s.setup_.effects.fracture) compute_damage(s.bonds_, s.p_, s.setup_.partial_volume);
    s.build_state_model();  // derived from the rebuilt rows
    plan_levels_alone(s);   // derived: the levels, their plans and forces (docs/theory.md §19)
  }

  template <class V>
  static bool in_range(const V& v, std::int64_t lo, std::int64_t hi) {
    return std::all_of(v.begin(), v.end(), [&](auto x) { return x >= lo && x < hi; });
  }

  /// Row i of every one of n rows lies inside an arena of `slots` entries.
  static bool rows_fit(const RowIndex& r, std::size_t n, std::size_t slots) {
    if (r.rows() != n || r.count.size() != n || r.capacity.size() != n) return false;
    if (r.arena < 0 || static_cast<std::size_t>(r.arena) != slots) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (r.start[i] < 0 || r.count[i] < 0 || r.count[i] > r.capacity[i] ||
          r.start[i] + r.capacity[i] > r.arena)
        return false;
    return true;
  }

  static bool particles_fit(const Simulation& s) {
    const std::size_t n = s.p_.size();
    for (auto& f : const_cast<ParticleStore&>(s.p_).fields()) {
      const bool sized = std::visit(
          [n](const auto* data) {
            if constexpr (std::is_same_v<std::decay_t<decltype(*data)>, VectorArray>)
              return (*data)[0].size() == n && (*data)[1].size() == n && (*data)[2].size() == n;
            else
              return data->size() == n;
          },
          f.data);
      if (!sized) return false;
    }
    const auto materials = static_cast<std::int64_t>(s.setup_.materials.size());
    return in_range(s.p_.material, 0, materials) && s.C_.size() == n && s.s0_.size() == n &&
           s.particle_dt_.size() == n;
  }

  /// Sizes and indices agree with each other, so no later access leaves the arrays.
  static void check_consistent(const Simulation& s, const archive::Reader& ar) {
    if (!particles_fit(s)) ar.fail("its particle arrays do not fit together");
    const auto n = static_cast<std::int64_t>(s.p_.size());
    const auto& b = s.bonds_;
    const std::size_t slots = b.other.size();
    const auto& l = s.loads_;
    const auto lengths = std::max<std::int64_t>(1, std::ssize(b.inverse_lengths));
    const bool ok = rows_fit(b.rows, s.p_.size(), slots) && b.length_index.size() == slots &&
                    in_range(b.length_index, 0, lengths) && b.flags.size() == slots &&
                    b.stiffness.size() == slots && (b.factor.empty() || b.factor.size() == slots) &&
                    (b.dilatation_factor.empty() || b.dilatation_factor.size() == slots) &&
                    b.break_ratio2.size() == s.p_.size() && in_range(b.other, -1, n) &&
                    b.stiffness_scale > 0.0 && in_range(l.prescribed, 0, n) &&
                    in_range(l.loaded, 0, n) && l.mask.size() == l.prescribed.size() &&
                    l.prescribed_velocity.size() == l.prescribed.size() &&
                    l.prescribed_displacement.size() == l.prescribed.size() &&
                    l.condition.size() == l.prescribed.size() &&
                    l.body_force.size() == l.loaded.size();
    if (!ok) ar.fail("its bond-row or load arrays do not fit together");
  }
};

}  // namespace dhpd
