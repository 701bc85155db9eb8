// The run loop: step, diagnose, write history and frames, summarise; stop cleanly when unstable.
#include "tools/runner.hpp"

#include <fmt/core.h>
#include <omp.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "engine/errors.hpp"
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
  fs::path dir;
  io::FrameSeries frames;
  io::HistoryWriter history;
  std::vector<std::string> fields;
  std::int64_t total_steps;

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
  fmt::print("dhpd: active effects: elasticity{}; threads {}; output in {}\n",
             s.effects.fracture ? ", fracture" : "", omp_get_max_threads(), dir.string());
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
}

}  // namespace

void run_scene(const scene::Scene& s, const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const auto start = Clock::now();
  auto sim = scene::build_simulation(s);  // every check happens here, before any output
  const std::int64_t steps = scene::planned_steps(s, sim->dt());
  const fs::path dir = opt.output_directory.value_or(s.output.directory);
  fs::create_directories(dir);
  auto resolved = s;
  resolved.output.directory = dir.string();  // where this run really writes
  write_text(dir / "scene.resolved.yaml",
             scene::resolved_yaml(resolved) + "---\n" + scene::derived_yaml(s, *sim));
  if (opt.echo) log_start(s, *sim, steps, dir);
  const auto particles_start = static_cast<std::int64_t>(sim->particles().size());
  RunContext ctx{s,
                 *sim,
                 dir,
                 io::FrameSeries(dir.string(), s.name),
                 io::HistoryWriter((dir / "history.csv").string()),
                 output_field_names(s),
                 steps};
  io::Progress progress(steps, opt.progress && io::Progress::wanted());
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  try {
    ctx.record(true);
    const auto frames_at = frame_steps(s, steps);
    std::size_t next_frame = 0;
    for (std::int64_t k = 1; k <= steps; ++k) {
      sim->step();
      const bool frame = next_frame < frames_at.size() && frames_at[next_frame] == k;
      next_frame += frame ? 1 : 0;
      if (frame || k % s.output.history_every == 0 || k == steps) ctx.record(frame);
      progress.update(k, sim->time(), sim->broken_bonds(), elapsed());
    }
    progress.finish();
  } catch (const InstabilityError& e) {
    progress.finish();
    auto sum = make_summary(s, *sim, elapsed(), particles_start);
    sum.status = "unstable";
    sum.message = e.what();
    io::write_summary((dir / "summary.json").string(), sum);
    if (opt.echo) log_end(sum);
    throw;
  }
  const auto sum = make_summary(s, *sim, elapsed(), particles_start);
  io::write_summary((dir / "summary.json").string(), sum);
  if (opt.echo) log_end(sum);
}

void check_scene(const scene::Scene& s, std::ostream& out) {
  auto sim = scene::build_simulation(s);
  out << "scene '" << s.name << "' (" << s.file << ") is valid\n";
  out << scene::derived_yaml(s, *sim);
}

}  // namespace dhpd
