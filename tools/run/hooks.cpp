// Frame schedule, refinement log and log lines of a run (see run_parts.hpp).
#include "tools/run/hooks.hpp"

#include <fmt/format.h>
#include <omp.h>

namespace dhpd::run {

namespace fs = std::filesystem;

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

std::vector<io::MaterialCount> material_counts(const scene::Scene& s, const Simulation& sim) {
  std::vector<io::MaterialCount> counts;
  for (const auto& m : s.materials) counts.push_back({m.name});
  const ParticleStore& p = sim.particles();
  const BondRows& b = sim.bonds();
  for (std::size_t i = 0; i < p.size(); ++i) {
    io::MaterialCount& c = counts.at(static_cast<std::size_t>(p.material[i]));
    std::int64_t broken = 0, own = 0;
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t) {
      broken += b.own_intact(k) ? 0 : 1;
      ++own;
    });
    c.particles += 1;
    c.bonds += own;
    c.broken_bonds += broken;
    c.damaged_particles += broken > 0 ? 1 : 0;
  }
  return counts;
}

void RefinementHook::log(const Simulation& sim, const refine::RefinementEvent& ev) {
  io::RefinementRow r;
  r.generation = ev.generation;
  // In a static run: the load step the event came in (between its relaxations) and its factor.
  const bool static_run = sim.is_static();
  r.step = sim.steps_done() + (static_run && sim.solving_load_step() ? 1 : 0);
  r.time = static_run ? sim.load_factor() : sim.time();
  r.parents = static_cast<std::int64_t>(ev.parents);
  r.children = static_cast<std::int64_t>(ev.children);
  r.dropped = static_cast<std::int64_t>(ev.dropped);
  r.particles = static_cast<std::int64_t>(sim.particles().size());
  r.bonds = static_cast<std::int64_t>(ev.bonds);
  r.rows_rebuilt = static_cast<std::int64_t>(ev.rows_rebuilt);
  r.bonds_rebuilt = static_cast<std::int64_t>(ev.bonds_rebuilt);
  r.rows_touched = static_cast<std::int64_t>(ev.rows_touched);
  r.started_broken = ev.started_broken;
  r.started_overstretched = ev.started_overstretched;
  r.mapping_energy = ev.energy_change;
  r.reduced_fits = static_cast<std::int64_t>(ev.reduced_fits);
  r.dt = sim.dt();
  r.seconds = ev.seconds;
  r.resorted = ev.resorted ? 1 : 0;
  r.resort_seconds = ev.resort_seconds;
  csv->write(r);
  ++events;
  const auto when = static_run ? fmt::format("in load step {} (load factor {:.4g})", r.step, r.time)
                               : fmt::format("at step {} (t = {:.4g} s)", r.step, r.time);
  log_lines.line(fmt::format(
      "dhpd: refinement {} {}: {} parents -> {} children; {} particles; {} rows, {} bonds "
      "rebuilt ({} start broken by no-healing, {} overstretched){}{}; {:.4f} s{}",
      r.generation, when, r.parents, r.children, r.particles, r.rows_rebuilt, r.bonds_rebuilt,
      r.started_broken, r.started_overstretched,
      static_run ? std::string() : fmt::format("; dt = {:.4g} s", r.dt),
      sim.time_levels()
          ? fmt::format(" over {} time levels (particles {})", sim.time_levels()->count(),
                        fmt::join(sim.particles_per_level(), " / "))
          : "",
      r.seconds, ev.resorted ? fmt::format(" (+ re-sort {:.4f} s)", ev.resort_seconds) : ""));
}

namespace {

/// One line per measured tip: initiation, angle, speeds against c_R, branchings.
void log_cracks(RunLog& log, const io::CrackReport& report) {
  const double c_r = report.rayleigh_speed;
  for (const auto& c : report.cracks) {
    auto text = [](const std::optional<double>& v, const char* format) {
      return v ? fmt::format(fmt::runtime(format), *v) : std::string("none");
    };
    log.line(fmt::format(
        "dhpd: crack {}: initiation {} s, angle {} deg at {} horizons, {} deg at the end, max "
        "speed {} m/s ({} c_R), mean {} m/s, {} branching(s){}",
        c.name, text(c.initiation_time, "{:.4g}"), text(c.initial_angle_deg, "{:.1f}"),
        measure::kInitialHorizons, text(c.angle_deg, "{:.1f}"), text(c.max_speed, "{:.4g}"),
        text(c.max_speed ? std::optional<double>(*c.max_speed / c_r) : std::nullopt, "{:.2f}"),
        text(c.mean_speed, "{:.4g}"), c.branch_times.size(),
        c.branch_times.empty()
            ? ""
            : fmt::format(" at {:.4g} s (tip speed {:.4g} m/s)", fmt::join(c.branch_times, ", "),
                          fmt::join(c.branch_speeds, ", "))));
  }
}

}  // namespace

void log_start(RunLog& log, const scene::Scene& s, const Simulation& sim, std::int64_t steps,
               const fs::path& dir) {
  log.line(fmt::format("dhpd: scene '{}' ({}), {}D, model {}, partial volume {}", s.name, s.file,
                       s.dimension, to_string(s.model), to_string(s.partial_volume)));
  if (s.statics)
    log.line(fmt::format(
        "dhpd: {} particles, {} bonds in {} row entries; static: {} load step{} by adaptive "
        "dynamic relaxation to {:g} of the load",
        sim.particles().size(), sim.bonds().bond_count(), sim.bonds().live, steps,
        steps == 1 ? "" : "s", s.statics->tolerance));
  else
    log.line(fmt::format(
        "dhpd: {} particles, {} bonds in {} row entries; dt = {:.4g} s (stable {:.4g} s), {} "
        "steps{}",
        sim.particles().size(), sim.bonds().bond_count(), sim.bonds().live, sim.dt(),
        sim.critical_dt(), steps, s.refinement ? " at the start (refinement shortens dt)" : ""));
  if (const auto* levels = sim.time_levels())  // dt is dt0: say what the finest particles take
    log.line(
        fmt::format("dhpd: {} time levels (docs/theory.md §19): particles {}; steps dt0 = "
                    "{:.4g} s down to {:.4g} s",
                    levels->count(), fmt::join(sim.particles_per_level(), " / "), levels->dt0,
                    levels->dt(levels->count() - 1)));
  log.line(fmt::format("dhpd: active effects: elasticity{}{}; threads {}; output in {}",
                       s.effects.fracture ? ", fracture" : "", s.refinement ? ", refinement" : "",
                       omp_get_max_threads(), dir.string()));
}

void log_end(RunLog& log, const io::Summary& sum) {
  log.line(
      fmt::format("dhpd: {} in {:.3f} s: {} steps, {} broken bonds, {:.3g} bond updates/s, {:.3g} "
                  "particle-steps/s, peak memory {:.0f} MB",
                  sum.status, sum.wall_seconds, sum.steps, sum.broken_bonds,
                  sum.bond_updates_per_second, sum.particle_steps_per_second, sum.peak_memory_mb));
  std::string phases;
  for (const auto& p : sum.phases) phases += fmt::format(" {} {:.3f} s;", p.name, p.seconds);
  log.line(fmt::format("dhpd: time per phase:{}", phases));
  if (sum.cracks) log_cracks(log, *sum.cracks);
}

EditTask RefinementHook::between_relaxations(Simulation& sim, std::function<bool()> stop) {
  return [this, &sim, stop = std::move(stop)] {
    if (stop()) return false;
    const auto ev = refiner.check(sim);
    if (ev.parents > 0) log(sim, ev);
    return ev.parents > 0;
  };
}

}  // namespace dhpd::run
