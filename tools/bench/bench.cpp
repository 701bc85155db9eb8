// Throughput benchmark. An interaction is one entry of a particle's own or dual list, so a bond
// counts twice under dual-horizon (once for its owner, once as a reaction on its neighbour).
#include "tools/bench/bench.hpp"

#include <fmt/core.h>
#include <fmt/ostream.h>
#include <omp.h>
#include <algorithm>
#include <chrono>
#include <ostream>

#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"

namespace dhpd {
namespace {

SimulationSetup lattice_setup(const BenchOptions& o, bool fracture) {
  SimulationSetup s;
  s.section.dim = 3;
  s.horizon_factor = o.horizon_factor;
  s.materials.push_back({72e9, 2440.0, 3.8});
  const double dx = 1e-3;
  s.points = geometry::fill_lattice(
      {{geometry::Box{{0, 0, 0}, {o.cells * dx, o.cells * dx, o.cells * dx}}, dx, 0}}, 3);
  // A small uniform strain so every bond carries force (and none breaks).
  InitialCondition ic;
  ic.region = geometry::Box{{-1, -1, -1}, {1, 1, 1}};
  ic.strain = Vec3{1e-5, -2e-5, 3e-5};
  ic.velocity = Vec3{0.1, 0.0, -0.1};
  s.initial_conditions.push_back(ic);
  s.effects.fracture = fracture;
  return s;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <class F>
double median_seconds(int repeats, F&& f) {
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    samples.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return median(samples);
}

struct Row {
  int threads;
  double kernel_ns, step_elastic_s, step_fracture_s;
};

}  // namespace

void run_bench(const BenchOptions& o, std::ostream& out) {
  Simulation elastic(lattice_setup(o, false));
  Simulation fracture(lattice_setup(o, true));
  const auto n = static_cast<double>(elastic.particles().size());
  const auto interactions = static_cast<double>(elastic.interactions().size());
  fmt::print(out,
             "dhpd bench: 3D lattice {}³ = {:.0f} particles, m = {}, {} bonds, {:.0f} interactions "
             "({:.1f} per particle)\n",
             o.cells, n, o.horizon_factor, elastic.bonds().size(), interactions, interactions / n);
  fmt::print(out, "median of {} samples of {} steps each\n\n", o.repeats, o.steps);
  std::vector<Row> rows;
  for (const int t : o.threads) {
    omp_set_num_threads(t);
    Row r{t, 0, 0, 0};
    const double kernel = median_seconds(o.repeats, [&] {
      for (int k = 0; k < o.steps; ++k)
        internal_force_density(elastic.interactions(), elastic.particles());
    });
    r.kernel_ns = kernel / o.steps / interactions * 1e9;
    r.step_elastic_s = median_seconds(o.repeats, [&] { elastic.run_steps(o.steps); }) / o.steps;
    r.step_fracture_s = median_seconds(o.repeats, [&] { fracture.run_steps(o.steps); }) / o.steps;
    rows.push_back(r);
  }
  fmt::print(out, "{:>8} {:>16} {:>22} {:>20} {:>22} {:>16}\n", "threads", "ns/interaction",
             "ns/interaction/core", "particle-steps/s", "p-steps/s (fracture)", "fracture cost");
  for (const auto& r : rows)
    fmt::print(out, "{:>8} {:>16.3f} {:>22.3f} {:>20.4g} {:>22.4g} {:>15.2f}x\n", r.threads,
               r.kernel_ns, r.kernel_ns * r.threads, n / r.step_elastic_s, n / r.step_fracture_s,
               r.step_fracture_s / r.step_elastic_s);
  if (rows.size() > 1)
    fmt::print(out, "\nspeed-up {} -> {} threads: kernel {:.2f}x, step {:.2f}x\n",
               rows.front().threads, rows.back().threads,
               rows.front().kernel_ns / rows.back().kernel_ns,
               rows.front().step_elastic_s / rows.back().step_elastic_s);
}

}  // namespace dhpd
