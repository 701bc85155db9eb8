// Throughput benchmark (docs/verification.md, "Performance"). The unit is ns per directed bond per
// core for the whole step: a directed bond is one bond i→j (one entry of a full neighbour list), so
// one unordered pair inside both horizons is two, as LAMMPS and CabanaPD count.
#include "tools/bench/bench.hpp"

#include <fmt/core.h>
#include <fmt/ostream.h>
#include <omp.h>
#include <algorithm>
#include <chrono>
#include <memory>
#include <ostream>

#include "engine/simulation.hpp"
#include "tools/bench/bench_plate.hpp"
#include "tools/bench/lammps_deck.hpp"
#include "tools/run/provenance.hpp"

namespace dhpd {
namespace {
using bench::Plate;
}  // namespace

SimulationSetup bench::common_setup(double horizon_factor, const Material& m, bool fracture) {
  SimulationSetup s;
  s.section.dim = 3;
  s.horizon_factor = horizon_factor;
  s.materials.push_back(m);
  // Linear partial volumes keep the bonds |ξ| ≤ δ, the set LAMMPS's peri/pmb builds.
  s.partial_volume = PartialVolume::Linear;
  s.effects.fracture = fracture;
  return s;
}

SimulationSetup bench::plate_setup(const Plate& pl, bool fracture) {
  auto s = common_setup(pl.horizon_factor, {pl.E, pl.rho, pl.G0}, fracture);
  auto& pts = s.points;
  for (int k = 0; k < pl.nz; ++k)
    for (int j = 0; j < pl.ny; ++j)
      for (int i = 0; i < pl.nx; ++i) {
        if (pl.in_notch(i, j)) continue;
        pts.position.push_back({(i + 0.5) * pl.dx, (j + 0.5) * pl.dx, (k + 0.5) * pl.dx});
        pts.cell_measure.push_back(pl.dx * pl.dx * pl.dx);
        pts.spacing.push_back(pl.dx);
        pts.material.push_back(0);
        pts.part.push_back(0);
      }
  InitialCondition impact;
  const double y1 = (pl.ny / 4 + 2) * pl.dx, y2 = (3 * pl.ny / 4 - 2) * pl.dx;
  impact.region = geometry::Box{{-1, y1, -1}, {3 * pl.dx, y2, 1}};
  impact.velocity = Vec3{pl.impact_speed, 0, 0};
  s.initial_conditions.push_back(impact);
  return s;
}

namespace {
using bench::common_setup;
using bench::plate_setup;

/// A cube of cells³ sites under a small uniform strain (every bond carries force, none breaks).
SimulationSetup lattice_setup(const BenchOptions& o, bool fracture) {
  auto s = common_setup(o.horizon_factor, {72e9, 2440.0, 3.8}, fracture);
  const double dx = 1e-3, L = o.cells * dx;
  s.points = geometry::fill_lattice({{geometry::Box{{0, 0, 0}, {L, L, L}}, dx, 0}}, 3);
  InitialCondition ic;
  ic.region = geometry::Box{{-1, -1, -1}, {1, 1, 1}};
  ic.strain = Vec3{1e-5, -2e-5, 3e-5};
  ic.velocity = Vec3{0.1, 0.0, -0.1};
  s.initial_conditions.push_back(ic);
  return s;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// Median wall seconds per step of `repeats` samples of `steps` steps (set-up excluded).
double seconds_per_step(Simulation& sim, int steps, int repeats) {
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    sim.run_steps(steps);
    samples.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return median(samples) / steps;
}

void print_row(std::ostream& out, const std::string& engine, const std::string& cores,
               const char* fracture, double ns_per_bond, double ms_per_step) {
  fmt::print(out, "{:<18} {:>8} {:>9} {:>16.2f} {:>12.2f}\n", engine, cores, fracture, ns_per_bond,
             ms_per_step);
}

struct DhpdTimes {
  std::vector<double> fracture_ns_by_threads;
  std::string phases;  ///< where the time of the first fracture run went
};

/// "forces 80 %, integrate 12 %, ..." of the timed steps (set-up excluded).
std::string phase_shares(const PhaseTimers& before, const PhaseTimers& after) {
  double total = 0;
  std::vector<double> s(static_cast<int>(Phase::Count));
  for (int p = 0; p < static_cast<int>(Phase::Count); ++p)
    total += s[p] = after.seconds(Phase(p)) - before.seconds(Phase(p));
  std::string out;
  for (int p = 0; p < static_cast<int>(Phase::Count); ++p)
    if (s[p] > 0.005 * total)
      out += fmt::format("{}{} {:.0f} %", out.empty() ? "" : ", ", phase_name(Phase(p)),
                         100 * s[p] / total);
  return out;
}

/// `make_setup(fracture)`: the body's setup, built for each run (a held setup would hold a copy
/// of every point beside the simulation's particles).
template <class MakeSetup>
DhpdTimes time_dhpd(const BenchOptions& o, MakeSetup make_setup, double bonds, std::ostream& out) {
  DhpdTimes t;
  for (const int threads : o.threads) {
    omp_set_num_threads(threads);
    for (const bool fracture : {false, true}) {
      Simulation sim(make_setup(fracture));
      const PhaseTimers before = sim.timers();
      const double s = seconds_per_step(sim, o.steps, o.repeats);
      if (fracture && t.phases.empty()) t.phases = phase_shares(before, sim.timers());
      const double ns = s * 1e9 * threads / bonds;
      print_row(out, "dhpd", fmt::format("{}", threads), fracture ? "on" : "off", ns, s * 1e3);
      if (fracture) t.fracture_ns_by_threads.push_back(ns);
    }
    // The state-based families without fracture (docs/theory.md §20, §21): two passes each.
    for (const auto family : {ModelFamily::OrdinaryState, ModelFamily::Correspondence}) {
      auto setup = make_setup(false);
      setup.family = family;
      for (auto& m : setup.materials) m.nu = 0.25;
      Simulation sim(std::move(setup));
      const double s = seconds_per_step(sim, o.steps, o.repeats);
      print_row(out,
                family == ModelFamily::OrdinaryState ? "dhpd state-based" : "dhpd correspondence",
                fmt::format("{}", threads), "off", s * 1e9 * threads / bonds, s * 1e3);
    }
  }
  return t;
}

void print_memory(std::ostream& out, const Simulation& sim) {
  const auto m = sim.memory_use();
  const double n = static_cast<double>(sim.particles().size());
  const double bonds = static_cast<double>(sim.bonds().bond_count());
  fmt::print(out,
             "dhpd memory: {:.0f} B per particle allocated ({:.1f} B per directed bond): bond rows "
             "{:.0f}, particle fields {:.0f}, other {:.0f} B per particle; peak RSS of this "
             "process {:.0f} MB\n",
             m.total() / n, m.total() / bonds, m.bonds / n, m.particles / n, m.other / n,
             run::peak_memory_mb());
}

void compare_lammps(const BenchOptions& o, const Plate& plate, double bonds, double particles,
                    const DhpdTimes& ours, std::ostream& out) {
  if (o.lammps == "off") return;
  const std::string command = o.lammps == "auto" ? "lmp" : o.lammps;
  std::vector<double> ratios;
  double rss = 0;
  for (std::size_t t = 0; t < o.threads.size(); ++t) {
    const int ranks = o.threads[t];
    std::vector<double> samples, pair;
    std::string why;
    for (int r = 0; r < o.repeats; ++r) {
      const auto run = bench::run_lammps(command, plate, o.steps, ranks, why);
      if (!run) break;
      if (run->atoms != static_cast<long>(particles))
        fmt::print(out, "(LAMMPS made {} atoms, dhpd {:.0f}: the lattices differ)\n", run->atoms,
                   particles);
      samples.push_back(run->loop_seconds / o.steps);
      pair.push_back(run->pair_seconds / o.steps);
      if (ranks == 1) rss = static_cast<double>(run->peak_rss_bytes);
    }
    if (samples.empty()) {
      fmt::print(out, "LAMMPS with {} rank(s) not run: {}\n", ranks, why);
      if (o.lammps == "auto" && t == 0) return;
      continue;
    }
    const double s = median(samples);
    const double ns = s * 1e9 * ranks / bonds;
    print_row(out, "LAMMPS peri/pmb", fmt::format("{} rank{}", ranks, ranks > 1 ? "s" : ""), "on",
              ns, s * 1e3);
    ratios.push_back(ns / ours.fracture_ns_by_threads[t]);
  }
  for (std::size_t t = 0; t < ratios.size(); ++t)
    fmt::print(out, "dhpd is {:.2f}x faster than LAMMPS per directed bond with {} core(s)\n",
               ratios[t], o.threads[t]);
  if (rss > 0)
    fmt::print(out, "LAMMPS memory: peak RSS {:.0f} B per particle ({:.0f} MB, 1 rank)\n",
               rss / particles, rss / 1048576.0);
}

}  // namespace

void run_bench(const BenchOptions& o, std::ostream& out) {
  const Plate plate;
  const bool on_plate = o.cells == 0;
  const auto make_setup = [&](bool fracture) {
    return on_plate ? plate_setup(plate, fracture) : lattice_setup(o, fracture);
  };
  // The counts and the memory line come from one body, freed before the timed ones are built.
  auto probe = std::make_unique<Simulation>(make_setup(true));
  const auto n = static_cast<double>(probe->particles().size());
  const auto bonds = static_cast<double>(probe->bonds().bond_count());
  if (on_plate)
    fmt::print(out, "dhpd bench: Kalthoff-Winkler plate {} x {} x {} sites, dx = {} mm, ", plate.nx,
               plate.ny, plate.nz, plate.dx * 1e3);
  else
    fmt::print(out, "dhpd bench: cubic lattice {}^3, ", o.cells);
  fmt::print(out,
             "{:.0f} particles, m = {}, {:.0f} directed bonds ({:.1f} per particle)\n"
             "whole step; median of {} samples of {} steps; ns per directed bond per core = "
             "wall time per step x cores / directed bonds\n\n",
             n, o.horizon_factor, bonds, bonds / n, o.repeats, o.steps);
  print_memory(out, *probe);
  probe.reset();
  fmt::print(out, "\n{:<18} {:>8} {:>9} {:>16} {:>12}\n", "engine", "cores", "fracture",
             "ns/bond/core", "ms/step");
  const auto ours = time_dhpd(o, make_setup, bonds, out);
  fmt::print(out, "dhpd phases (fracture on, {} thread{}): {}\n", o.threads.front(),
             o.threads.front() > 1 ? "s" : "", ours.phases);
  if (on_plate) compare_lammps(o, plate, bonds, n, ours, out);
}

}  // namespace dhpd
