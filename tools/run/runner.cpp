// The run loop: step, diagnose, write history and frames, summarise; stop cleanly when unstable.
#include "tools/run/runner.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "refine/refiner.hpp"
#include "tools/output/frame_fields.hpp"
#include "tools/output/text_outputs.hpp"
#include "tools/output/vtk_writer.hpp"
#include "tools/run/checkpoints.hpp"
#include "tools/run/hooks.hpp"
#include "tools/run/restart.hpp"
#include "tools/run/signals.hpp"
#include "tools/scene/build.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using run::CrackHook;
using run::RefinementHook;
using run::Schedule;

std::vector<std::string> output_field_names(const scene::Scene& s) {
  auto names = scene::default_fields();
  for (const auto& f : s.output.fields) names.push_back(f);
  return names;
}

io::HistoryRow history_row(const Simulation& sim, const Energies& e) {
  io::HistoryRow r;
  r.step = sim.steps_done();
  r.time = sim.time();
  r.dt = sim.dt();
  r.particles = static_cast<std::int64_t>(sim.particles().size());
  r.bonds = static_cast<std::int64_t>(sim.bonds().size());
  r.broken_bonds = sim.broken_bonds();
  r.kinetic_energy = e.kinetic;
  r.strain_energy = e.strain;
  r.external_work = e.external_work;
  for (int a = 0; a < 3; ++a) r.momentum[a] = e.momentum[a];
  return r;
}

/// The newest state that passed the guard's full check (Simulation::check_stable), kept in memory
/// so an unstable run can still write it as its final frame and checkpoint. Taken at history rows
/// at most every kLastGoodEvery steps (the branching plate: 5 copies and 46 history checks
/// together take 0.1 s of a 3.9 s run).
struct LastGood {
  static constexpr std::int64_t kLastGoodEvery = 100;
  std::vector<std::byte> simulation;
  RunState run;
  std::optional<measure::CrackTracker> cracks;
  std::int64_t step = -1;
};

struct RunContext {
  const scene::Scene& scene;
  Simulation& sim;
  io::FrameSeries frames;
  io::HistoryWriter history;
  std::vector<std::string> fields;
  CrackHook* cracks = nullptr;     ///< with `measure` only
  RefinementHook* hook = nullptr;  ///< with `effects.refinement` only
  Schedule* schedule = nullptr;
  RunState* state = nullptr;  ///< what a checkpoint saves besides the simulation
  std::string scene_text{};   ///< checkpoint_scene_text of the scene
  fs::path checkpoint_file{};
  std::function<double()> elapsed{};  ///< wall seconds of this process
  double wall_before = 0.0;           ///< wall seconds of the runs this one continues
  bool echo = true;                   ///< a log line per checkpoint
  LastGood good{};

  /// Measures the cracks at measurement steps and at the last step.
  void measure(bool last) {
    if (cracks && (last || cracks->tracker.due(sim.steps_done()))) cracks->take_measurement(sim);
  }
  void write_frame() {
    auto t = sim.timers().scope(Phase::Output);
    if (sim.setup().effects.fracture) sim.update_damage();
    frames.write(sim.time(), sim.steps_done(), io::frame_points(sim),
                 io::frame_fields(sim, fields));
  }
  void record(bool frame) {
    const auto e = sim.energies();
    sim.check_stable(e);  // throws before anything of this state is written
    {
      auto t = sim.timers().scope(Phase::Output);
      history.write(history_row(sim, e));
    }
    if (frame) write_frame();
    if (good.step < 0 || sim.steps_done() - good.step >= LastGood::kLastGoodEvery) keep_good();
  }
  /// The run loop's state now (what a checkpoint of the current state saves).
  RunState run_state() {
    RunState st = *state;
    st.schedule_position = schedule->position();
    st.frames = frames.entries();
    st.history_bytes = history.bytes();
    st.refinement_bytes = hook ? hook->csv->bytes() : 0;
    st.cracks_bytes = cracks ? cracks->csv.bytes() : 0;
    st.refinement_events = hook ? hook->events : 0;
    st.wall_seconds = wall_before + elapsed();
    return st;
  }
  void keep_good() {
    auto t = sim.timers().scope(Phase::Diagnostics);
    save_simulation_into(sim, good.simulation);  // in place: never two copies at once
    good.run = run_state();
    if (cracks) good.cracks = cracks->tracker;
    good.step = sim.steps_done();
  }
  /// After the guard stopped the run: the last good state becomes the final frame (unless a later
  /// good frame exists) and the checkpoint. Returns what was written, for the message.
  std::string write_last_good() {
    if (good.step < 0) return "";
    load_simulation(good.simulation, sim, "the last good state");
    if (cracks && good.cracks) cracks->tracker = *good.cracks;
    const auto& written = frames.entries();
    const bool good_frame = !written.empty() && written.back().first >= sim.time();
    if (!good_frame) {
      write_frame();
      good.run.frames = frames.entries();
    }
    write_checkpoint(checkpoint_file.string(), sim, good.run, scene_text);
    return fmt::format(
        "; the last good state (step {}, t = {:.6g} s) is in {}{}", good.step, sim.time(),
        checkpoint_file.string(),
        good_frame ? " and the last frame passed the check" : " and written as the final frame");
  }
  /// Whether step k writes a checkpoint: every output.checkpoint_every steps (never for 0).
  bool checkpoint_due(std::int64_t k) const {
    const auto every = scene.output.checkpoint_every;
    return every && *every > 0 && k % *every == 0;
  }
  /// The checkpoint of the state after the current step; it changes no state of the run.
  void checkpoint() {
    auto& st = *state;
    st = run_state();
    auto t = sim.timers().scope(Phase::Output);
    const auto begin = Clock::now();
    const auto bytes = write_checkpoint(checkpoint_file.string(), sim, st, scene_text);
    if (echo)
      fmt::print("dhpd: checkpoint after step {}: {} ({:.1f} MB in {:.3f} s)\n", sim.steps_done(),
                 checkpoint_file.string(), static_cast<double>(bytes) / 1e6,
                 std::chrono::duration<double>(Clock::now() - begin).count());
  }
};

io::Summary make_summary(const scene::Scene& s, const Simulation& sim, double wall,
                         std::int64_t particles_start) {
  io::Summary sum;
  sum.scene_name = s.name;
  sum.scene_file = s.file;
  sum.wall_seconds = wall;
  sum.steps = sim.steps_done();
  sum.end_time = sim.time();
  sum.dt = sim.dt();
  sum.critical_dt = sim.critical_dt();
  sum.particles_start = particles_start;
  sum.particles_end = static_cast<std::int64_t>(sim.particles().size());
  sum.bonds = static_cast<std::int64_t>(sim.bonds().size());
  sum.broken_bonds = sim.broken_bonds();
  const double force_s = std::max(sim.timers().seconds(Phase::Forces), 1e-12);
  sum.bond_updates_per_second = static_cast<double>(sim.interaction_updates()) / force_s;
  sum.particle_steps_per_second = static_cast<double>(sim.steps_done()) *
                                  static_cast<double>(sum.particles_end) / std::max(wall, 1e-12);
  sum.threads = omp_get_max_threads();
  sum.active_effects.push_back("elasticity");
  if (s.effects.fracture) sum.active_effects.push_back("fracture");
  if (s.refinement) sum.active_effects.push_back("refinement");
  for (int p = 0; p < static_cast<int>(Phase::Count); ++p)
    sum.phases.push_back({std::string(phase_name(static_cast<Phase>(p))),
                          sim.timers().seconds(static_cast<Phase>(p))});
  sum.materials = run::material_counts(s, sim);
  return sum;
}

/// SIGINT/SIGTERM after step k: the checkpoint of this state (unless step k just wrote it), then
/// a final frame (unless step k wrote one), then RunInterrupted.
[[noreturn]] void interrupt(RunContext& ctx, int signal, std::int64_t k, bool frame_written) {
  if (!ctx.checkpoint_due(k)) ctx.checkpoint();
  if (!frame_written) ctx.write_frame();
  const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
  throw RunInterrupted(
      signal, fmt::format("{} after step {} (t = {:.6g} s); checkpoint {}; continue with: dhpd run "
                          "{} --out DIR --restart {}",
                          name, k, ctx.sim.time(), ctx.checkpoint_file.string(), ctx.scene.file,
                          ctx.checkpoint_file.parent_path().string()));
}

/// Steps until the schedule says the run is over; refinement checks after each due step, crack
/// measurements at step 0, every `measure.every` steps and at the last step; checkpoints every
/// output.checkpoint_every steps and at the end. A restarted run starts after its checkpoint.
void time_loop(RunContext& ctx, io::Progress& progress) {
  auto& sim = ctx.sim;
  auto& schedule = *ctx.schedule;
  auto* hook = ctx.hook;
  const std::int64_t first = sim.steps_done() + 1;
  if (first == 1) {
    ctx.record(true);
    ctx.measure(false);
  }
  const InterruptSignals signals;
  for (std::int64_t k = first; !schedule.finished(k - 1, sim.time()); ++k) {
    sim.step();
    if (hook && hook->refiner.due(k)) {
      const auto ev = hook->refiner.check(sim);
      if (ev.parents > 0) hook->log(sim, ev);
    }
    const bool frame = schedule.frame(k, sim.time());
    if (frame || k % ctx.scene.output.history_every == 0) ctx.record(frame);
    const bool last = schedule.finished(k, sim.time());
    ctx.measure(last);
    progress.update(k, sim.time(), sim.broken_bonds(), ctx.elapsed());
    if (last) break;
    if (ctx.checkpoint_due(k)) ctx.checkpoint();
    if (const int signal = signals.caught()) {
      progress.finish();
      interrupt(ctx, signal, k, frame);
    }
  }
  progress.finish();
  if (ctx.scene.output.checkpoint_every.value_or(1) != 0) ctx.checkpoint();
}

/// The CSV files whose length a checkpoint records.
std::vector<CsvLength> csv_lengths(const scene::Scene& s, const RunState& st) {
  std::vector<CsvLength> out{{"history.csv", st.history_bytes}};
  if (s.refinement) out.push_back({"refinement.csv", st.refinement_bytes});
  if (s.measure) out.push_back({"cracks.csv", st.cracks_bytes});
  return out;
}

/// A new run at step 0: the zones are refined first, then what the outputs report is fixed.
void start_run(const scene::Scene& s, Simulation& sim, RefinementHook* hook, RunState& st) {
  if (hook) hook->pending = hook->refiner.refine_zones(sim);
  st.planned_steps = scene::planned_steps(s, sim.dt());
  st.particles_start = static_cast<std::int64_t>(sim.particles().size());
  st.derived_text = scene::derived_yaml(s, sim);
  if (s.measure)
    st.rayleigh_speed =
        measure::rayleigh_speed_near(sim.particles(), sim.setup().materials, sim.setup().section,
                                     s.measure->settings.tips.front().at);
}

/// A restarted run: the simulation and `st` from the checkpoint; returns the first run's folder.
/// Everything is checked before anything is written.
fs::path resume_run(const scene::Scene& s, const RunOptions& opt, Simulation& sim, RunState& st) {
  const auto file = checkpoint_path(*opt.restart_from);
  load_checkpoint(file, sim, st, checkpoint_scene_text(s));
  const fs::path from = fs::path(file).has_parent_path() ? fs::path(file).parent_path() : ".";
  check_restart_outputs(from, st, csv_lengths(s, st));
  if (opt.echo)
    fmt::print("dhpd: restarting from {} after step {} (t = {:.6g} s)\n", file, sim.steps_done(),
               sim.time());
  return from;
}

/// Creates `dir`; restarting, continues the first run's outputs there; otherwise removes the
/// checkpoints of an older run whose outputs this one replaces.
void prepare_folder(const scene::Scene& s, const fs::path& dir, const std::optional<fs::path>& from,
                    const RunState& state) {
  fs::create_directories(dir);
  if (from) {
    continue_outputs(*from, dir, state, csv_lengths(s, state));
    return;
  }
  std::error_code ec;
  fs::remove(dir / "checkpoint.bin", ec);
  fs::remove(dir / "checkpoint.prev.bin", ec);
}

/// Opens (or, restarting, continues) the outputs in `dir`.
RunContext open_outputs(const scene::Scene& s, Simulation& sim, const fs::path& dir,
                        RunState& state, bool resumed) {
  auto resolved = s;
  resolved.output.directory = dir.string();  // where this run really writes
  io::write_text_atomically((dir / "scene.resolved.yaml").string(),
                            scene::resolved_yaml(resolved) + "---\n" + state.derived_text);
  RunContext ctx{s, sim, io::FrameSeries(dir.string(), s.name),
                 io::HistoryWriter((dir / "history.csv").string(), resumed), output_field_names(s)};
  if (resumed) ctx.frames.resume(state.frames);
  ctx.state = &state;
  ctx.scene_text = checkpoint_scene_text(s);
  ctx.checkpoint_file = dir / "checkpoint.bin";
  ctx.wall_before = state.wall_seconds;
  return ctx;
}

}  // namespace

void run_scene(const scene::Scene& s, const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const auto start = Clock::now();
  auto sim = scene::build_simulation(s);  // every check happens here, before any output
  std::unique_ptr<RefinementHook> hook;
  if (s.refinement) hook = std::make_unique<RefinementHook>(s.refinement->settings, opt.echo);
  std::optional<measure::CrackTracker> tracker;
  if (s.measure) tracker.emplace(s.measure->settings);
  RunState state;
  state.cracks = tracker ? &*tracker : nullptr;
  std::optional<fs::path> from;
  if (opt.restart_from)
    from = resume_run(s, opt, *sim, state);
  else
    start_run(s, *sim, hook.get(), state);
  const fs::path dir = opt.output_directory.value_or(s.output.directory);
  prepare_folder(s, dir, from, state);
  auto ctx = open_outputs(s, *sim, dir, state, from.has_value());
  if (opt.echo) run::log_start(s, *sim, state.planned_steps, dir);
  if (hook) {
    hook->refiner.prepare(*sim);  // the events' search, before the first one is timed
    hook->events = state.refinement_events;
    hook->csv =
        std::make_unique<io::RefinementWriter>((dir / "refinement.csv").string(), from.has_value());
    for (const auto& ev : hook->pending) hook->log(*sim, ev);
  }
  std::unique_ptr<CrackHook> cracks;
  if (s.measure) {
    cracks = std::make_unique<CrackHook>(*s.measure, std::move(*tracker), dir, from.has_value(),
                                         state.rayleigh_speed);
    state.cracks = &cracks->tracker;
  }
  Schedule schedule(s, state.planned_steps, s.refinement && s.time.end);
  if (from) schedule.resume(state.schedule_position);
  ctx.cracks = cracks.get();
  ctx.hook = hook.get();
  ctx.schedule = &schedule;
  ctx.echo = opt.echo;
  ctx.elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  io::Progress progress(state.planned_steps, opt.progress && io::Progress::wanted(),
                        sim->steps_done());
  const auto finish = [&](const char* status, const std::string& message) {
    auto sum = make_summary(s, *sim, ctx.wall_before + ctx.elapsed(), state.particles_start);
    sum.status = status;
    sum.message = message;
    sum.refinement_events = hook ? hook->events : 0;
    if (cracks) sum.cracks = cracks->report();
    io::write_summary((dir / "summary.json").string(), sum);
    if (opt.echo) run::log_end(sum);
  };
  try {
    time_loop(ctx, progress);
  } catch (const InstabilityError& e) {
    progress.finish();
    const std::string message = e.what() + ctx.write_last_good();
    finish("unstable", message);
    throw InstabilityError(message);
  } catch (const RunInterrupted& e) {
    finish("interrupted", e.what());
    throw;
  }
  finish("completed", "");
}

void check_scene(const scene::Scene& s, std::ostream& out) {
  auto sim = scene::build_simulation(s);
  out << "scene '" << s.name << "' (" << s.file << ") is valid\n";
  out << scene::derived_yaml(s, *sim);
}

}  // namespace dhpd
