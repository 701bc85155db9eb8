// `dhpd bench --refinement`: what one refinement event costs as the body grows. The same refined
// set (discs of parents on a crack line, identical surroundings) is split in bodies of N, 4N and
// 16N particles; an incremental event should cost the same in all of them. The occasional
// re-sort (compaction) is timed separately and amortised over the events that make it due.
#include <fmt/core.h>
#include <fmt/ostream.h>
#include <algorithm>
#include <cmath>
#include <ostream>

#include "engine/simulation.hpp"
#include "refine/event.hpp"
#include "tools/bench/bench.hpp"

namespace dhpd {
namespace {

constexpr double kSpacing = 1e-3;
constexpr double kDiscRadius = 5e-3;

/// A plane-stress glass plate of nx × ny cells whose upper half is lifted by a tenth of a
/// spacing: the first step breaks every bond across the mid-line (a crack of broken bonds).
SimulationSetup cracked_plate(int nx, int ny) {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1.0};
  s.materials = {{72e9, 2440, 135.0}};
  s.partial_volume = PartialVolume::Linear;
  const double lx = nx * kSpacing, ly = ny * kSpacing;
  s.points = geometry::fill_lattice({{geometry::Box{{0, 0, 0}, {lx, ly, 0}}, kSpacing, 0}}, 2);
  InitialCondition lift;
  lift.region = geometry::Box{{0, 0.5 * ly, 0}, {lx, ly, 0}};
  lift.displacement = Vec3{0, 0.1 * kSpacing, 0};
  s.initial_conditions = {lift};
  s.effects.fracture = true;
  s.effects.refinement = true;
  s.resort_fraction = 0.0;  // re-sorts are timed on their own below
  return s;
}

std::vector<std::int32_t> disc(const ParticleStore& p, double cx, double cy) {
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::hypot(p.reference_position[0][i] - cx, p.reference_position[1][i] - cy) < kDiscRadius)
      out.push_back(static_cast<std::int32_t>(i));
  return out;
}

struct BodyResult {
  std::size_t particles = 0, bonds = 0, parents = 0, children = 0, rows = 0;
  double median_s = 0, max_s = 0, resort_s = 0;
};

BodyResult time_body(int nx, int ny, int events) {
  Simulation sim(cracked_plate(nx, ny));
  sim.step();
  BodyResult r;
  r.particles = sim.particles().size();
  r.bonds = sim.bonds().bond_count();
  const double cx = 0.5 * nx * kSpacing, cy = 0.5 * ny * kSpacing;
  std::vector<double> seconds;
  refine::EventSearch search;
  search.grid(sim);  // built once, as a run's refiner does before its first event
  for (int e = 0; e < events; ++e) {
    // Disc centres 15 mm apart along the crack, symmetric about the body's centre.
    const double x = cx + 15e-3 * (e - 0.5 * (events - 1));
    const auto ev =
        refine::split(sim, disc(sim.particles(), x, cy), refine::StateMapping::Linear, &search);
    seconds.push_back(ev.seconds);
    r.parents += ev.parents, r.children += ev.children, r.rows += ev.rows_rebuilt;
  }
  r.parents /= events, r.children /= events, r.rows /= events;
  r.max_s = *std::max_element(seconds.begin(), seconds.end());
  std::sort(seconds.begin(), seconds.end());
  r.median_s = seconds[seconds.size() / 2];
  r.resort_s = sim.compact();
  return r;
}

}  // namespace

void run_refinement_bench(const BenchOptions& o, std::ostream& out) {
  const int events = std::max(3, o.repeats);
  fmt::print(out,
             "dhpd bench --refinement: 2D cracked plate, Δx = 1 mm, discs of radius 5 mm on the "
             "crack split per event ({} events per body, median and max)\n\n",
             events);
  fmt::print(out, "{:>10} {:>10} {:>8} {:>9} {:>9} {:>11} {:>9} {:>8} {:>11} {:>14}\n", "particles",
             "bonds", "parents", "children", "rows", "event (ms)", "max (ms)", "vs N", "re-sort ms",
             "amortised ms");
  BodyResult first;
  for (const int scale : {1, 2, 4}) {  // 1, 4, 16 times the particles
    const auto r = time_body(100 * scale, 80 * scale, events);
    if (scale == 1) first = r;
    // A re-sort is due once appended children exceed 20 % of the particles.
    const double appended_per_event = static_cast<double>(r.children - r.parents);
    const double events_per_resort = 0.2 * static_cast<double>(r.particles) / appended_per_event;
    fmt::print(out,
               "{:>10} {:>10} {:>8} {:>9} {:>9} {:>11.3f} {:>9.3f} {:>7.2f}x {:>11.2f} {:>14.3f}\n",
               r.particles, r.bonds, r.parents, r.children, r.rows, 1e3 * r.median_s, 1e3 * r.max_s,
               r.median_s / first.median_s, 1e3 * r.resort_s, 1e3 * r.resort_s / events_per_resort);
  }
  fmt::print(out,
             "\n'vs N': median event time relative to the smallest body (incremental: ≈ 1). "
             "'amortised': the re-sort's cost spread over the events between two re-sorts.\n");
}

}  // namespace dhpd
