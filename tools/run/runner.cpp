// The run loop: step, diagnose, write history and frames, summarise; stop cleanly when unstable.
#include "tools/run/runner.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <chrono>
#include <cmath>
#include <csignal>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "refine/refiner.hpp"
#include "tools/cli/version.hpp"
#include "tools/output/frame_fields.hpp"
#include "tools/output/text_outputs.hpp"
#include "tools/output/units.hpp"
#include "tools/output/vtk_writer.hpp"
#include "tools/run/checkpoints.hpp"
#include "tools/run/hooks.hpp"
#include "tools/run/provenance.hpp"
#include "tools/run/restart.hpp"
#include "tools/run/run_context.hpp"
#include "tools/run/run_folder.hpp"
#include "tools/run/run_log.hpp"
#include "tools/run/signals.hpp"
#include "tools/run/time_loop.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/estimate.hpp"
#include "tools/scene/warnings.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using run::CrackHook;
using run::LastGood;
using run::output_field_names;
using run::RefinementHook;
using run::RunContext;
using run::Schedule;

io::Summary make_summary(const scene::Scene& s, const Simulation& sim, double wall,
                         std::int64_t particles_start, const RunOptions& opt) {
  io::Summary sum;
  sum.version = dhpd_version();
  sum.commit = dhpd_commit();
  sum.command_line = run::shell_command(opt.command_words);
  sum.peak_memory_mb = run::peak_memory_mb();
  const auto m = sim.memory_use();
  sum.allocated = {static_cast<std::int64_t>(m.total()), static_cast<std::int64_t>(m.particles),
                   static_cast<std::int64_t>(m.bonds), static_cast<std::int64_t>(m.other)};
  sum.scene_name = s.name;
  sum.scene_file = s.file;
  sum.wall_seconds = wall;
  sum.steps = sim.steps_done();
  sum.end_time = sim.time();
  sum.dt = sim.dt();
  sum.critical_dt = sim.critical_dt();
  sum.particles_start = particles_start;
  sum.particles_end = static_cast<std::int64_t>(sim.particles().size());
  sum.bonds = static_cast<std::int64_t>(sim.bonds().bond_count());
  sum.broken_bonds = sim.broken_bonds();
  const double force_s = std::max(sim.timers().seconds(Phase::Forces), 1e-12);
  sum.bond_updates_per_second = static_cast<double>(sim.bond_updates()) / force_s;
  sum.particle_steps_per_second = static_cast<double>(sim.steps_done()) *
                                  static_cast<double>(sum.particles_end) / std::max(wall, 1e-12);
  sum.threads = omp_get_max_threads();
  if (const auto* share = sim.force_share()) {
    sum.ranks = share->comm().size();
    sum.partitioner = std::string(distributed::name_of(share->method()));
    sum.imbalance = share->stats().imbalance;
    sum.values_shared = share->stats().values_shared;
    sum.repartitions = share->stats().repartitions;
    sum.moved = share->stats().moved;
  }
  sum.active_effects.push_back("elasticity");
  if (s.effects.fracture) sum.active_effects.push_back("fracture");
  if (s.refinement) sum.active_effects.push_back("refinement");
  for (int p = 0; p < static_cast<int>(Phase::Count); ++p)
    sum.phases.push_back({std::string(phase_name(static_cast<Phase>(p))),
                          sim.timers().seconds(static_cast<Phase>(p))});
  sum.materials = run::material_counts(s, sim);
  if (run::reports_time_levels(s, sim)) {
    io::Summary::TimeLevels t;
    t.particles = sim.particles_per_level();
    t.evaluated = sim.level_counts().evaluated;
    t.one_step = sim.level_counts().one_step;
    sum.time_levels = std::move(t);
  }
  return sum;
}

/// The CSV files whose length a checkpoint records.
std::vector<CsvLength> csv_lengths(const scene::Scene& s, const RunState& st) {
  std::vector<CsvLength> out{{"history.csv", st.history_bytes}};
  if (s.refinement) out.push_back({"refinement.csv", st.refinement_bytes});
  if (s.measure) out.push_back({"cracks.csv", st.cracks_bytes});
  if (s.statics) out.push_back({"relaxation.csv", st.relaxation_bytes});
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
fs::path resume_run(const scene::Scene& s, const RunOptions& opt, Simulation& sim, RunState& st,
                    run::RunLog& log) {
  const auto file = checkpoint_path(*opt.restart_from);
  load_checkpoint(file, sim, st, checkpoint_scene_text(s));
  const fs::path from = fs::path(file).has_parent_path() ? fs::path(file).parent_path() : ".";
  check_restart_outputs(from, st, csv_lengths(s, st));
  log.line(fmt::format("dhpd: restarting from {} after step {} (t = {:.6g} s)", file,
                       sim.steps_done(), sim.time()));
  return from;
}

/// Creates `dir` (run::claim_folder has made sure no other run's outputs are in it); restarting,
/// continues the first run's outputs there.
void prepare_folder(const scene::Scene& s, const fs::path& dir, const std::optional<fs::path>& from,
                    const RunState& state) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw IoError(fmt::format("cannot create the output folder '{}': {}", dir.string(),
                              ec ? ec.message() : "a file of that name is in the way"));
  if (from) continue_outputs(*from, dir, state, csv_lengths(s, state));
}

/// The folder of a --restart argument (a folder, or a checkpoint file in one).
fs::path run_folder_of(const std::string& restart) {
  const fs::path p(restart);
  if (fs::is_directory(p)) return p;
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

bool same_folder(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec) || fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

/// Opens (or, restarting, continues) the outputs in `dir`.
RunContext open_outputs(const scene::Scene& s, Simulation& sim, const fs::path& dir,
                        RunState& state, bool resumed) {
  auto resolved = s;
  resolved.output.directory = dir.string();  // where this run really writes
  io::write_text_atomically((dir / "scene.resolved.yaml").string(),
                            scene::resolved_yaml(resolved) + "---\n" + state.derived_text);
  std::vector<std::string> materials;
  for (const auto& m : s.materials) materials.push_back(m.name);
  io::write_text_atomically((dir / "units.json").string(), io::units_json());
  // Room kept for summary.json: released just before it is written, so a run stopped by a full
  // disk still leaves its summary (status io_error).
  io::write_text_atomically((dir / "summary.reserve").string(), std::string(65536, ' '));
  const auto compression = s.output.compression == "zlib"   ? io::Compression::zlib
                           : s.output.compression == "none" ? io::Compression::none
                                                            : io::Compression::lz4;
  // Frames while the run goes on: by one thread of the next step's force pass when the team has
  // every core (a thread of their own would take a core from it), on a thread of their own when a
  // core is spare, at once on one core (docs/outputs.md, "Frames in the background").
  const auto cores = static_cast<int>(std::thread::hardware_concurrency());
  const int team = omp_get_max_threads();
  const auto frame_mode = team > 1 && team >= cores ? io::BackgroundFrames::Mode::Shared
                          : cores > 1               ? io::BackgroundFrames::Mode::Thread
                                                    : io::BackgroundFrames::Mode::Now;
  auto probes = run::probes_of(s);
  auto probe_columns = io::static_columns(s);
  for (auto& column : io::probe_columns(probes, s.dimension)) probe_columns.push_back(column);
  RunContext ctx{s,
                 sim,
                 io::BackgroundFrames(io::FrameSeries(dir.string(), s.name, materials, compression),
                                      frame_mode),
                 io::HistoryWriter((dir / "history.csv").string(), resumed,
                                   run::reports_time_levels(s, sim) ? s.time.max_levels : 0,
                                   std::move(probe_columns)),
                 output_field_names(s, sim),
                 std::move(probes)};
  if (resumed) ctx.frames.resume(state.frames);
  if (s.statics)
    ctx.relaxation =
        std::make_unique<io::RelaxationWriter>((dir / "relaxation.csv").string(), resumed);
  ctx.state = &state;
  ctx.scene_text = checkpoint_scene_text(s);
  ctx.checkpoint_file = dir / "checkpoint.bin";
  ctx.wall_before = state.wall_seconds;
  return ctx;
}

/// Before each refinement event: a line for a large one, and a stop (ResourceLimit) for one whose
/// result would not fit the budget: the resident memory now plus the children's particles and about
/// 3·2^d·(bonds per particle) bonds per parent (their own rows, the neighbours' rows that reach
/// them, the garbage the moved rows leave until the next compaction), with the run's copies of
/// its state (scene::run_bytes).
refine::Refiner::EventCheck event_check(run::RunLog& log, double budget, bool given) {
  return [&log, budget, given](const Simulation& sim, std::size_t parents) {
    const int dim = sim.particles().dim();
    const double split = std::pow(2.0, dim), n = static_cast<double>(parents);
    const double per_particle_bonds = static_cast<double>(sim.bonds().bond_count()) /
                                      std::max<double>(1.0, sim.particles().size());
    // What the process holds now (program, libraries, state, its copies), or at least what
    // run_bytes gives for its particles and bonds; the event adds (2^d − 1) particles and
    // 3·2^d·(bonds per particle) bonds per parent.
    const double now = std::max(scene::estimated_memory_bytes(sim), run::current_memory_mb() * 1e6);
    const double after =
        now + scene::run_bytes((split - 1.0) * n, 3.0 * split * per_particle_bonds * n,
                               sim.setup().model, true);
    if (parents >= 10000)
      log.line(
          fmt::format("dhpd: refinement: splitting {} parents at step {} (a large event; "
                      "about {:.0f} MB after it)",
                      parents, sim.steps_done(), after / 1e6));
    if (after > budget)
      throw ResourceLimit(fmt::format(
          "refinement stopped before splitting {} parents at step {} (t = {:.6g} s): the run "
          "would need about {:.3g} GB, more than the {:.3g} GB {} (the run has {} particles; "
          "lower max_level, raise the triggers, limit refinement with `within`{})",
          parents, sim.steps_done(), sim.time(), after / 1e9, budget / 1e9,
          given ? "--max-memory allows" : "available", sim.particles().size(),
          given ? ", or raise --max-memory" : ""));
  };
}

/// The checks before a run, the same on every rank: the folder (another run's outputs are refused
/// before anything is built or written) and the memory budget. Returns the budget.
double check_before_build(const scene::Scene& s, const RunOptions& opt, const fs::path& dir,
                          bool own_folder, run::RunLog& log) {
  if (!own_folder && !opt.overwrite)
    run::claim_folder(dir, false, opt.restart_from ? "the restarted run" : "a new run");
  const auto estimate = scene::estimate_resources(s);
  const double budget = scene::memory_budget_bytes(opt.max_memory_mb);
  scene::refuse_if_too_big(s, estimate, budget, opt.max_memory_mb.has_value());
  log.line(
      fmt::format("dhpd: set-up: about {:.4g} particles, {:.4g} bonds, {:.0f} MB (of {:.0f} "
                  "MB available)",
                  estimate.particles, estimate.bonds, estimate.bytes / 1e6, budget / 1e6));
  return budget;
}

/// A distributed run's decomposition (docs/theory.md §25), after the checkpoint is loaded.
void distribute(Simulation& sim, const RunOptions& opt, run::RunLog& log) {
  if (!opt.comm || opt.comm->size() == 1) return;
  sim.distribute(opt.comm, opt.partition, opt.repartition);
  const auto& st = sim.force_share()->stats();
  log.line(fmt::format("dhpd: {} ranks: Zoltan {} partition, load imbalance {:.3f} ({:.3f} s)",
                       opt.comm->size(), distributed::name_of(opt.partition), st.imbalance,
                       st.partition_seconds));
}

/// A restarted run's crack tracker and run state, as resume_run fills them.
struct Resumed {
  std::optional<measure::CrackTracker> tracker;
  RunState state;
};
}  // namespace

void serve_scene(const scene::Scene& s, const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  run::RunLog log(false);
  const fs::path dir = opt.output_directory.value_or(s.output.directory);
  const bool own_folder = opt.restart_from && same_folder(run_folder_of(*opt.restart_from), dir);
  check_before_build(s, opt, dir, own_folder, log);
  auto sim = scene::build_simulation(s);
  std::optional<refine::Refiner> refiner;
  if (s.refinement) refiner.emplace(s.refinement->settings);
  if (opt.restart_from) {
    Resumed r;
    if (s.measure) r.tracker.emplace(s.measure->settings);
    r.state.cracks = r.tracker ? &*r.tracker : nullptr;
    resume_run(s, opt, *sim, r.state, log);
  } else if (refiner) {
    refiner->refine_zones(*sim);  // as start_run on rank 0
  }
  distribute(*sim, opt, log);
  if (refiner) {
    refiner->prepare(*sim);
    // Every event waits for rank 0's verdict on its memory budget (its event check).
    refiner->set_event_check([](const Simulation& state_now, std::size_t) {
      if (!state_now.agree(true))
        throw StoppedByRankZero("rank 0 refused the refinement event (memory budget)");
    });
  }
  // SIGINT / SIGTERM (mpirun sends them to every rank) are rank 0's to act on: it finishes the
  // step, writes its checkpoint with this rank's help and then releases it.
  std::signal(SIGINT, SIG_IGN);
  std::signal(SIGTERM, SIG_IGN);
  // A static load step checks the triggers between its relaxations, on every rank alike.
  const EditTask between = [&] { return refiner->check(*sim).parents > 0; };
  sim->serve([&] { refiner->check(*sim); }, refiner && sim->is_static() ? &between : nullptr);
}

void run_scene(const scene::Scene& s, const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const auto start = Clock::now();
  run::RunLog log(opt.echo);
  const fs::path dir = opt.output_directory.value_or(s.output.directory);
  const bool own_folder = opt.restart_from && same_folder(run_folder_of(*opt.restart_from), dir);
  const double budget = check_before_build(s, opt, dir, own_folder, log);
  auto sim = scene::build_simulation(s);  // every check happens here, before any output
  std::unique_ptr<RefinementHook> hook;
  if (s.refinement) hook = std::make_unique<RefinementHook>(s.refinement->settings, log);
  std::optional<measure::CrackTracker> tracker;
  if (s.measure) tracker.emplace(s.measure->settings);
  RunState state;
  state.cracks = tracker ? &*tracker : nullptr;
  std::optional<fs::path> from;
  if (opt.restart_from)
    from = resume_run(s, opt, *sim, state, log);
  else
    start_run(s, *sim, hook.get(), state);
  distribute(*sim, opt, log);
  // Whatever ends this run on rank 0 (completion, an error of its own) lets the other ranks go.
  const struct Release {
    Simulation& sim;
    ~Release() { sim.release_ranks(); }
  } release{*sim};
  if (!own_folder && opt.overwrite) run::claim_folder(dir, true, "");
  prepare_folder(s, dir, from, state);
  log.open((dir / "run.log").string(), from.has_value() && same_folder(*from, dir));
  auto ctx = open_outputs(s, *sim, dir, state, from.has_value());
  run::log_start(log, s, *sim, state.planned_steps, dir);
  auto warnings = scene::scene_warnings(s, *sim, state.planned_steps);
  if (const int cores = static_cast<int>(std::thread::hardware_concurrency());
      cores > 0 && omp_get_max_threads() > cores)
    warnings.push_back(
        fmt::format("--threads {}: this machine has {} cores; more threads than "
                    "cores only slow the run down",
                    omp_get_max_threads(), cores));
  for (const auto& w : warnings) log.line("dhpd: warning: " + w);
  if (hook) {
    hook->refiner.prepare(*sim);  // the events' search, before the first one is timed
    // The guard's copy keeps the discretisation its step part belongs to before an event edits it.
    // Under mpirun the other ranks take rank 0's verdict before they split anything (§25.3).
    hook->refiner.set_event_check([check = event_check(log, budget, opt.max_memory_mb.has_value()),
                                   &ctx](const Simulation& state_now, std::size_t parents) {
      try {
        check(state_now, parents);
      } catch (const ResourceLimit&) {
        state_now.agree(false);
        throw;
      }
      state_now.agree(true);
      ctx.good.simulation.before_edit(state_now);
    });
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
  ctx.log = &log;
  ctx.command_words = opt.command_words;
  ctx.elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  io::Progress progress(state.planned_steps, opt.progress && io::Progress::wanted(),
                        sim->steps_done(), s.time.end);
  const auto finish = [&](const char* status, const std::string& message) {
    auto sum = make_summary(s, *sim, ctx.wall_before + ctx.elapsed(), state.particles_start, opt);
    sum.status = status;
    sum.message = message;
    sum.warnings = warnings;
    sum.refinement_events = hook ? hook->events : 0;
    if (cracks) {
      cracks->flush_quietly();
      sum.cracks = cracks->report();
    }
    std::error_code ec;
    fs::remove(dir / "summary.reserve", ec);
    io::write_summary((dir / "summary.json").string(), sum);
    run::log_end(log, sum);
  };
  try {
    run::time_loop(ctx, progress);
  } catch (const InstabilityError& e) {
    progress.finish();
    const std::string message = e.what() + ctx.write_last_good();
    finish("unstable", message);
    throw InstabilityError(message);
  } catch (const RunInterrupted& e) {
    finish("interrupted", e.what());
    throw;
  } catch (const IoError& e) {
    progress.finish();
    // The summary is written when the disk still takes it; every frame already written is whole.
    std::string message = e.what();
    try {
      finish("io_error", message);
    } catch (const IoError& again) {
      message += std::string("; summary.json could not be written either: ") + again.what();
    }
    throw IoError(message);
  } catch (const ResourceLimit& e) {
    progress.finish();
    // The last good state, not the current one: a restart from it meets the refused event again
    // (a checkpoint after step k would skip step k's refinement check and differ from a run
    // with a larger budget).
    const std::string message = e.what() + ctx.write_last_good();
    finish("resource_limit", message);
    throw ResourceLimit(message);
  }
  finish("completed", ctx.unsaved);
}

}  // namespace dhpd
