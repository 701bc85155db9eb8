// The run loop: step, diagnose, write history and frames, summarise; stop cleanly when unstable.
#include "tools/runner.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>

#include "engine/errors.hpp"
#include "refine/refiner.hpp"
#include "tools/frame_fields.hpp"
#include "tools/run_outputs.hpp"
#include "tools/scene_build.hpp"
#include "tools/vtk_writer.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::vector<std::string> output_field_names(const scene::Scene& s) {
  auto names = scene::default_fields();
  for (const auto& f : s.output.fields) names.push_back(f);
  return names;
}

/// Steps at which frames are written after frame 0: every N steps, or F frames spread evenly.
std::vector<std::int64_t> frame_steps(const scene::Scene& s, std::int64_t total) {
  std::vector<std::int64_t> out;
  if (s.output.every) {
    for (std::int64_t k = *s.output.every; k < total; k += *s.output.every) out.push_back(k);
  } else {
    const std::int64_t frames = s.output.frames.value_or(20);
    for (std::int64_t k = 1; k < frames; ++k) {
      const std::int64_t step = (k * total + frames / 2) / frames;
      if (step > 0 && step < total && (out.empty() || out.back() != step)) out.push_back(step);
    }
  }
  if (total > 0) out.push_back(total);
  return out;
}

/// When a run ends and frames are due. A run with refinement and `time.end` runs to the end time
/// (dt changes at events), with `output.frames` spread over time; otherwise steps are planned.
class Schedule {
 public:
  Schedule(const scene::Scene& s, std::int64_t planned, bool by_time)
      : s_(s), planned_(planned), by_time_(by_time) {
    if (!by_time_) {
      steps_ = frame_steps(s, planned);
    } else if (!s.output.every) {
      const std::int64_t frames = s.output.frames.value_or(20);
      for (std::int64_t k = 1; k < frames; ++k)
        times_.push_back(*s.time.end * static_cast<double>(k) / static_cast<double>(frames));
    }
  }
  bool finished(std::int64_t k, double t) const {
    return by_time_ ? t >= *s_.time.end * (1.0 - 1e-12) : k >= planned_;
  }
  /// Whether step k (just done, at time t) writes a frame; call once per step.
  bool frame(std::int64_t k, double t) {
    if (finished(k, t)) return true;
    if (!by_time_) {
      const bool due = next_ < steps_.size() && steps_[next_] == k;
      next_ += due ? 1 : 0;
      return due;
    }
    if (s_.output.every) return k % *s_.output.every == 0;
    bool due = false;
    while (next_ < times_.size() && t >= times_[next_] * (1.0 - 1e-12)) due = true, ++next_;
    return due;
  }

 private:
  const scene::Scene& s_;
  std::int64_t planned_;
  bool by_time_;
  std::vector<std::int64_t> steps_;
  std::vector<double> times_;
  std::size_t next_ = 0;
};

/// The refiner of a scene with effects.refinement and its log (refinement.csv).
struct RefinementHook {
  RefinementHook(const refine::Settings& settings, bool echo_lines)
      : refiner(settings), echo(echo_lines) {}
  refine::Refiner refiner;
  std::vector<RefinementEvent> pending;  ///< zone events applied before the output existed
  std::unique_ptr<io::RefinementWriter> csv;
  bool echo = true;
  std::int64_t events = 0;

  void log(const Simulation& sim, const RefinementEvent& ev) {
    io::RefinementRow r;
    r.generation = ev.generation;
    r.step = sim.steps_done();
    r.time = sim.time();
    r.parents = static_cast<std::int64_t>(ev.parents);
    r.children = static_cast<std::int64_t>(ev.children);
    r.dropped = static_cast<std::int64_t>(ev.dropped);
    r.particles = static_cast<std::int64_t>(sim.particles().size());
    r.bonds = static_cast<std::int64_t>(ev.bonds);
    r.rows_rebuilt = static_cast<std::int64_t>(ev.rows_rebuilt);
    r.bonds_rebuilt = static_cast<std::int64_t>(ev.bonds_rebuilt);
    r.rows_touched = static_cast<std::int64_t>(ev.rows_touched);
    r.started_broken = ev.started_broken;
    r.dt = sim.dt();
    r.seconds = ev.seconds;
    r.resorted = ev.resorted ? 1 : 0;
    r.resort_seconds = ev.resort_seconds;
    csv->write(r);
    ++events;
    if (echo)
      fmt::print(
          "dhpd: refinement {} at step {} (t = {:.4g} s): {} parents -> {} children; {} "
          "particles; {} rows, {} bonds rebuilt ({} start broken); dt = {:.4g} s; {:.4f} s{}\n",
          r.generation, r.step, r.time, r.parents, r.children, r.particles, r.rows_rebuilt,
          r.bonds_rebuilt, r.started_broken, r.dt, r.seconds,
          ev.resorted ? fmt::format(" (+ re-sort {:.4f} s)", ev.resort_seconds) : "");
  }
};

/// Crack measurements of a scene with `measure`: cracks.csv and the summary's "cracks".
struct CrackHook {
  CrackHook(const scene::MeasureSpec& spec, const Simulation& sim, const fs::path& dir)
      : tracker(spec.settings),
        csv((dir / "cracks.csv").string(), tip_names(spec.settings)),
        published(spec.published),
        rayleigh_speed(measure::rayleigh_speed_near(sim.particles(), sim.setup().materials,
                                                    sim.setup().section,
                                                    spec.settings.tips.front().at)) {}
  measure::CrackTracker tracker;
  io::CrackWriter csv;
  std::optional<measure::Published> published;
  double rayleigh_speed;

  static std::vector<std::string> tip_names(const measure::Settings& s) {
    std::vector<std::string> names;
    for (const auto& t : s.tips) names.push_back(t.name);
    return names;
  }
  void take_measurement(Simulation& sim) {
    sim.update_damage();
    auto t = sim.timers().scope(Phase::Diagnostics);
    for (const auto& row : tracker.measure(sim.particles(), sim.steps_done(), sim.time()))
      csv.write(row);
  }
  io::CrackReport report() const { return {rayleigh_speed, tracker.summary(), published}; }
};

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

struct RunContext {
  const scene::Scene& scene;
  Simulation& sim;
  io::FrameSeries frames;
  io::HistoryWriter history;
  std::vector<std::string> fields;
  CrackHook* cracks = nullptr;  ///< with `measure` only

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
  return sum;
}

void write_text(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

void log_start(const scene::Scene& s, const Simulation& sim, std::int64_t steps,
               const fs::path& dir) {
  fmt::print("dhpd: scene '{}' ({}), {}D, model {}, partial volume {}\n", s.name, s.file,
             s.dimension, to_string(s.model), to_string(s.partial_volume));
  fmt::print(
      "dhpd: {} particles, {} bonds, {} interactions; dt = {:.4g} s (stable {:.4g} s), {} steps\n",
      sim.particles().size(), sim.bonds().size(), sim.interactions().size(), sim.dt(),
      sim.critical_dt(), steps);
  fmt::print("dhpd: active effects: elasticity{}{}; threads {}; output in {}\n",
             s.effects.fracture ? ", fracture" : "", s.refinement ? ", refinement" : "",
             omp_get_max_threads(), dir.string());
}

/// One line per measured tip: initiation, angle, speeds against c_R, branchings.
void log_cracks(const io::CrackReport& report) {
  const double c_r = report.rayleigh_speed;
  for (const auto& c : report.cracks) {
    auto text = [](const std::optional<double>& v, const char* format) {
      return v ? fmt::format(fmt::runtime(format), *v) : std::string("none");
    };
    fmt::print(
        "dhpd: crack {}: initiation {} s, angle {} deg, max speed {} m/s ({} c_R), mean {} m/s, "
        "{} branching(s){}\n",
        c.name, text(c.initiation_time, "{:.4g}"), text(c.angle_deg, "{:.1f}"),
        text(c.max_speed, "{:.4g}"),
        text(c.max_speed ? std::optional<double>(*c.max_speed / c_r) : std::nullopt, "{:.2f}"),
        text(c.mean_speed, "{:.4g}"), c.branch_times.size(),
        c.branch_times.empty() ? "" : fmt::format(" at {:.4g} s", fmt::join(c.branch_times, ", ")));
  }
}

void log_end(const io::Summary& sum) {
  fmt::print(
      "dhpd: {} in {:.3f} s: {} steps, {} broken bonds, {:.3g} bond updates/s, {:.3g} "
      "particle-steps/s\n",
      sum.status, sum.wall_seconds, sum.steps, sum.broken_bonds, sum.bond_updates_per_second,
      sum.particle_steps_per_second);
  std::string phases;
  for (const auto& p : sum.phases) phases += fmt::format(" {} {:.3f} s;", p.name, p.seconds);
  fmt::print("dhpd: time per phase:{}\n", phases);
  if (sum.cracks) log_cracks(*sum.cracks);
}

/// Steps until the schedule says the run is over; refinement checks after each due step, crack
/// measurements at step 0, every `measure.every` steps and at the last step.
void time_loop(RunContext& ctx, RefinementHook* hook, Schedule& schedule, io::Progress& progress,
               const std::function<double()>& elapsed) {
  auto& sim = ctx.sim;
  ctx.record(true);
  ctx.measure(false);
  for (std::int64_t k = 1; !schedule.finished(k - 1, sim.time()); ++k) {
    sim.step();
    if (hook && hook->refiner.due(k)) {
      const auto ev = hook->refiner.check(sim);
      if (ev.parents > 0) hook->log(sim, ev);
    }
    const bool frame = schedule.frame(k, sim.time());
    if (frame || k % ctx.scene.output.history_every == 0) ctx.record(frame);
    ctx.measure(schedule.finished(k, sim.time()));
    progress.update(k, sim.time(), sim.broken_bonds(), elapsed());
  }
  progress.finish();
}

}  // namespace

void run_scene(const scene::Scene& s, const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const auto start = Clock::now();
  auto sim = scene::build_simulation(s);  // every check happens here, before any output
  const auto particles_start = static_cast<std::int64_t>(sim->particles().size());
  std::unique_ptr<RefinementHook> hook;
  if (s.refinement) {
    hook = std::make_unique<RefinementHook>(s.refinement->settings, opt.echo);
    hook->pending = hook->refiner.refine_zones(*sim);
  }
  const std::int64_t steps = scene::planned_steps(s, sim->dt());
  const fs::path dir = opt.output_directory.value_or(s.output.directory);
  fs::create_directories(dir);
  auto resolved = s;
  resolved.output.directory = dir.string();  // where this run really writes
  write_text(dir / "scene.resolved.yaml",
             scene::resolved_yaml(resolved) + "---\n" + scene::derived_yaml(s, *sim));
  if (opt.echo) log_start(s, *sim, steps, dir);
  if (hook) {
    hook->csv = std::make_unique<io::RefinementWriter>((dir / "refinement.csv").string());
    for (const auto& ev : hook->pending) hook->log(*sim, ev);
  }
  std::unique_ptr<CrackHook> cracks;
  if (s.measure) cracks = std::make_unique<CrackHook>(*s.measure, *sim, dir);
  RunContext ctx{s,
                 *sim,
                 io::FrameSeries(dir.string(), s.name),
                 io::HistoryWriter((dir / "history.csv").string()),
                 output_field_names(s),
                 cracks.get()};
  Schedule schedule(s, steps, s.refinement && s.time.end);
  io::Progress progress(steps, opt.progress && io::Progress::wanted());
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  auto summary = [&](const char* status) {
    auto sum = make_summary(s, *sim, elapsed(), particles_start);
    sum.status = status;
    sum.refinement_events = hook ? hook->events : 0;
    if (cracks) sum.cracks = cracks->report();
    return sum;
  };
  try {
    time_loop(ctx, hook.get(), schedule, progress, elapsed);
  } catch (const InstabilityError& e) {
    progress.finish();
    auto sum = summary("unstable");
    sum.message = e.what();
    io::write_summary((dir / "summary.json").string(), sum);
    if (opt.echo) log_end(sum);
    throw;
  }
  const auto sum = summary("completed");
  io::write_summary((dir / "summary.json").string(), sum);
  if (opt.echo) log_end(sum);
}

void check_scene(const scene::Scene& s, std::ostream& out) {
  auto sim = scene::build_simulation(s);
  out << "scene '" << s.name << "' (" << s.file << ") is valid\n";
  out << scene::derived_yaml(s, *sim);
}

}  // namespace dhpd
