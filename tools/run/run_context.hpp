// The state of one run loop between its parts (runner.cpp): the outputs it writes, the hooks, the
// last good state the instability guard keeps, and checkpoints of the current state.
#pragma once
#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/checkpoint/guard_copy.hpp"
#include "engine/simulation.hpp"
#include "tools/output/background_frames.hpp"
#include "tools/output/frame_fields.hpp"
#include "tools/output/probes.hpp"
#include "tools/output/static_outputs.hpp"
#include "tools/output/text_outputs.hpp"
#include "tools/output/vtk_writer.hpp"
#include "tools/run/checkpoints.hpp"
#include "tools/run/hooks.hpp"
#include "tools/run/run_log.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::run {

namespace fs = std::filesystem;

/// Whether the run's outputs show time levels (frames' time_level, history's particles per level,
/// summary.json's time_levels): when time.multirate is true, or left to its default in a scene that
/// starts with several levels or refines (docs/theory.md §19.5).
inline bool reports_time_levels(const scene::Scene& s, const Simulation& sim) {
  if (s.time.multirate) return *s.time.multirate;
  return sim.multirate_enabled() && (s.refinement || sim.time_levels() != nullptr);
}

inline std::vector<std::string> output_field_names(const scene::Scene& s, const Simulation& sim) {
  auto names = scene::default_fields();
  for (const auto& f : s.output.fields) names.push_back(f);
  const bool listed = std::find(names.begin(), names.end(), "time_level") != names.end();
  if (reports_time_levels(s, sim) && !listed) names.push_back("time_level");
  const bool flagged = std::find(names.begin(), names.end(), "fictitious") != names.end();
  if (!sim.fictitious_layers().empty() && !flagged) names.push_back("fictitious");
  return names;
}

/// The scene's probes (output.probes) as the history writer takes them.
inline std::vector<io::Probe> probes_of(const scene::Scene& s) {
  std::vector<io::Probe> probes;
  for (const auto& p : s.output.probes) probes.push_back({p.name, p.at});
  return probes;
}

/// A history row; a static run's columns (io::static_columns) come before the probes'.
inline io::HistoryRow history_row(const scene::Scene& s, const Simulation& sim, const Energies& e,
                                  const std::vector<io::Probe>& probes) {
  io::HistoryRow r;
  r.step = sim.steps_done();
  r.time = sim.time();
  r.dt = sim.dt();
  r.particles = static_cast<std::int64_t>(sim.particles().size());
  r.bonds = static_cast<std::int64_t>(sim.bonds().bond_count());
  r.broken_bonds = sim.broken_bonds();
  r.kinetic_energy = e.kinetic;
  r.strain_energy = e.strain;
  r.external_work = e.external_work;
  for (int a = 0; a < 3; ++a) r.momentum[a] = e.momentum[a];
  r.particles_per_level = sim.particles_per_level();  // written when the history has the columns
  r.probe_values = io::static_values(s, sim);
  for (const double v : io::probe_values(sim.particles(), probes)) r.probe_values.push_back(v);
  return r;
}

/// The newest state that passed the guard's full check (Simulation::check_stable), kept in memory
/// so an unstable run can still write it as its final frame and checkpoint. Taken at history rows
/// at most every kLastGoodEvery steps; between refinement events only what steps change is copied
/// (GuardCopy; the default plate: 4.2 MB and 0.7 ms a copy, where the whole state is 35 MB and
/// 11 ms).
struct LastGood {
  static constexpr std::int64_t kLastGoodEvery = 100;
  GuardCopy simulation;
  RunState run;
  std::optional<measure::CrackTracker> cracks;
  std::int64_t step = -1;
};

struct RunContext {
  const scene::Scene& scene;
  Simulation& sim;
  io::BackgroundFrames frames;
  io::HistoryWriter history;
  std::vector<std::string> fields;
  std::vector<io::Probe> probes{};  ///< output.probes, columns of history.csv
  CrackHook* cracks = nullptr;      ///< with `measure` only
  RefinementHook* hook = nullptr;   ///< with `effects.refinement` only
  /// relaxation.csv of a static run (solver: static) only.
  std::unique_ptr<io::RelaxationWriter> relaxation{};
  Schedule* schedule = nullptr;
  RunState* state = nullptr;  ///< what a checkpoint saves besides the simulation
  std::string scene_text{};   ///< checkpoint_scene_text of the scene
  fs::path checkpoint_file{};
  std::function<double()> elapsed{};  ///< wall seconds of this process
  double wall_before = 0.0;           ///< wall seconds of the runs this one continues
  RunLog* log = nullptr;
  std::string unsaved{};  ///< why the final checkpoint is missing (the run still completed) ///< a
                          ///< log line per checkpoint
  std::vector<std::string> command_words{};  ///< the command line, for the restart hint
  LastGood good{};
  RangeTask frame_copy{};  ///< copies the frame handed over after the last step (or empty)

  /// The crack measurement of this step when due: deferred to the next force pass (CrackHook::
  /// defer_measurement) where frames are (a team on every core), at once for the last step.
  void measure(bool last) {
    if (!cracks || !(last || cracks->tracker.due(sim.steps_done()))) return;
    if (!last && frames.shared())
      cracks->defer_measurement(sim);
    else
      cracks->take_measurement(sim);
  }
  /// A frame of the current state. Where frames go to the next force passes, the particle
  /// store's fields are copied by the next step's threads before they change them
  /// (frame_before_change()); the frame's encoding finishes the copy when no step came first.
  void write_frame() {
    sim.share_bond_states();  // fields such as bond_count read every row
    auto t = sim.timers().scope(Phase::Output);
    if (!frames.shared()) {
      frames.write(sim.time(), sim.steps_done(), io::frame_points(sim),
                   io::frame_fields(sim, fields));
      return;
    }
    auto copy = std::make_shared<io::FrameCopy>(sim, fields, frames.take_spent());
    frame_copy = [copy](std::int64_t begin, std::int64_t end) { copy->copy(begin, end); };
    frames.write(sim.time(), sim.steps_done(), std::move(copy->points), std::move(copy->fields),
                 [copy] { copy->finish(); });
  }
  /// The copy of the frame handed over after the last step, for the next step's threads
  /// (StepExtras::before_change; nullptr when none waits). Valid until step_done().
  const RangeTask* frame_before_change() const { return frame_copy ? &frame_copy : nullptr; }
  /// After a step: the frame's copy is made (or is finish()ed where it is encoded).
  void step_done() { frame_copy = nullptr; }
  void record(bool frame) {
    const auto e = sim.energies();
    sim.check_stable(e);  // throws before anything of this state is written
    {
      auto t = sim.timers().scope(Phase::Output);
      history.write(history_row(scene, sim, e, probes));
    }
    if (frame) write_frame();
    // A static run's load steps are few and dear: each is kept.
    if (good.step < 0 || sim.is_static() ||
        sim.steps_done() - good.step >= LastGood::kLastGoodEvery)
      keep_good();
  }
  /// The run loop's state now (what a checkpoint of the current state saves). Without `frames`
  /// its list of frames stays empty and nothing waits for a frame in flight.
  /// `frames_listed`: the frames to list instead (entries_once_written()).
  RunState run_state(
      bool with_frames = true,
      std::optional<std::vector<std::pair<double, std::string>>> frames_listed = {}) {
    if (cracks) cracks->flush();
    RunState st = *state;
    st.schedule_position = schedule->position();
    if (frames_listed)
      st.frames = std::move(*frames_listed);
    else if (with_frames)
      st.frames = frames.entries();
    st.history_bytes = history.bytes();
    st.refinement_bytes = hook ? hook->csv->bytes() : 0;
    st.cracks_bytes = cracks ? cracks->csv.bytes() : 0;
    st.relaxation_bytes = relaxation ? relaxation->bytes() : 0;
    st.refinement_events = hook ? hook->events : 0;
    st.wall_seconds = wall_before + elapsed();
    return st;
  }
  void keep_good() {
    auto t = sim.timers().scope(Phase::Diagnostics);
    sim.share_bond_states();  // rank 0 of a distributed run keeps every row's bonds
    good.simulation.take(sim);
    good.run = run_state(false);  // its frames: those on disk when it is used (write_last_good)
    if (cracks) good.cracks = cracks->tracker;
    good.step = sim.steps_done();
  }
  /// After the guard stopped the run: the last good state becomes the final frame (unless a later
  /// good frame exists) and the checkpoint. Returns what was written, for the message.
  std::string write_last_good() {
    const std::string lost = frames.drain_quietly();
    if (good.step < 0) return lost.empty() ? "" : "; " + lost;
    try {
      good.simulation.restore(sim);
    } catch (const std::exception& e) {  // the stop's own message is what matters: keep it
      return fmt::format("; the last good state could not be restored ({}){}", e.what(),
                         lost.empty() ? "" : "; " + lost);
    }
    if (cracks && good.cracks) cracks->tracker = *good.cracks;
    const auto& written = frames.entries();
    // The good state's frames: those on disk up to its time (later ones are of later steps).
    good.run.frames.clear();
    for (const auto& f : written)
      if (f.first <= sim.time()) good.run.frames.push_back(f);
    const bool good_frame = !written.empty() && written.back().first >= sim.time();
    if (!good_frame) {
      write_frame();
      good.run.frames = frames.entries();
    }
    write_checkpoint(checkpoint_file.string(), sim, good.run, scene_text);
    return fmt::format(
        "; the last good state (step {}, t = {:.6g} s) is in {}{}{}", good.step, sim.time(),
        checkpoint_file.string(),
        good_frame ? " and the last frame passed the check" : " and written as the final frame",
        lost.empty() ? "" : "; " + lost);
  }
  /// Whether step k writes a checkpoint: every output.checkpoint_every steps (never for 0), and
  /// when output.checkpoint_minutes of wall time passed since the last one (or the start).
  bool checkpoint_due(std::int64_t k) const {
    const auto every = scene.output.checkpoint_every;
    if (every && *every == 0) return false;
    if (every && k % *every == 0) return true;
    const double minutes = scene.output.checkpoint_minutes;
    return minutes > 0 && elapsed() - last_checkpoint_wall >= 60.0 * minutes;
  }
  double last_checkpoint_wall = 0.0;  ///< wall seconds of this process at the last checkpoint
  /// The checkpoint of the state after the current step; it changes no state of the run.
  void checkpoint() {
    auto& st = *state;
    st = run_state();
    sim.share_bond_states();
    auto t = sim.timers().scope(Phase::Output);
    const auto begin = std::chrono::steady_clock::now();
    log_checkpoint(write_checkpoint(checkpoint_file.string(), sim, st, scene_text), begin);
  }
  /// After the last step: every frame on disk (a failed one throws its IoError) and the final
  /// checkpoint (one that cannot be written leaves `unsaved` and a warning: the run is complete).
  /// Where the last frame is still to be written by the run's threads, one thread finishes it while
  /// another writes and syncs the checkpoint under its temporary name; the checkpoint takes its
  /// name only once the frame is on disk, so it never lists a frame that is not.
  void finish_with_checkpoint();
  /// The run is complete without its final checkpoint: `unsaved` and a warning say why.
  void warn_unsaved(const IoError& e);
  void log_checkpoint(std::size_t bytes, std::chrono::steady_clock::time_point begin) {
    last_checkpoint_wall = elapsed();
    log->line(fmt::format(
        "dhpd: checkpoint after step {}: {} ({:.1f} MB in {:.3f} s)", sim.steps_done(),
        checkpoint_file.string(), static_cast<double>(bytes) / 1e6,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count()));
  }
};

}  // namespace dhpd::run
