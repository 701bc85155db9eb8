// `dhpd check`: validation, the resource estimate and, for a body small enough to build, its
// derived quantities, allocated bytes and stable step (docs/scenes.md).
#include <fmt/format.h>

#include <sstream>

#include "engine/physics/bond_loops.hpp"
#include "engine/physics/stable_step.hpp"
#include "tools/run/runner.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/estimate.hpp"
#include "tools/scene/warnings.hpp"

namespace dhpd {

void check_scene(const scene::Scene& s, std::ostream& printed, bool build,
                 std::optional<double> max_memory_mb) {
  std::ostringstream out;  // printed only when the whole check passes: an error prints nothing else
  const auto estimate = scene::estimate_resources(s);
  const double budget = scene::memory_budget_bytes(max_memory_mb);
  out << "scene '" << s.name << "' (" << s.file << ") is valid\n";
  out << scene::estimate_yaml(estimate, budget);
  if (estimate.bytes > budget)
    out << fmt::format(
        "warning: about {:.3g} GB needed, {:.3g} GB available: `dhpd run` refuses "
        "it\n",
        estimate.bytes / 1e9, budget / 1e9);
  else if (estimate.bytes > 0.5 * budget)
    out << fmt::format(
        "warning: about {:.3g} GB needed, more than half of the {:.3g} GB "
        "available\n",
        estimate.bytes / 1e9, budget / 1e9);
  if (estimate.bytes_worst > budget && estimate.particles_worst > estimate.particles)
    out << fmt::format(
        "warning: refinement could reach {:.3g} GB (every particle split down to "
        "max_level); the run stops cleanly before an event that would not fit\n",
        estimate.bytes_worst / 1e9);
  // A small scene is built anyway (about 0.5 s per million bonds here), so `check` finds every
  // error `run` would (regions that select nothing, a fixed step above the stable one).
  constexpr double kBuildWithoutAskingBonds = 1e6;
  if (!build && estimate.bonds > kBuildWithoutAskingBonds) {
    out << fmt::format(
        "built: no (about {:.3g} bonds; `dhpd check --build` builds the body and "
        "checks its regions, stable step and derived constants)\n",
        estimate.bonds);
    printed << out.str();
    return;
  }
  scene::refuse_if_too_big(s, estimate, budget, max_memory_mb.has_value());
  auto sim = scene::build_simulation(s);
  for (const auto& w : scene::scene_warnings(s, *sim, scene::planned_steps(s, sim->dt())))
    out << "warning: " << w << "\n";
  out << scene::derived_yaml(s, *sim);
  const auto m = sim->memory_use();
  const double n = static_cast<double>(sim->particles().size());
  const double bonds = std::max(1.0, static_cast<double>(sim->bonds().bond_count()));
  out << fmt::format(
      "allocated: {{bytes: {}, per_particle: {:.0f}, per_directed_bond: {:.1f}, bond_rows: {}, "
      "particle_fields: {}, other: {}}}\n",
      m.total(), m.total() / n, m.total() / bonds, m.bonds, m.particles, m.other);
  // The run's stable step (time.stable_step, docs/theory.md §9) beside both estimates.
  const double bound = critical_time_step(sim->bonds(), sim->particles());
  const bool tight = s.time.stable_step == StableStepEstimate::Lanczos;
  const double lanczos =
      tight ? sim->critical_dt() : lanczos_stable_step(sim->bonds(), sim->particles()).dt;
  out << fmt::format(
      "stable_step: {{run: {:.6g}, estimate: {}, bound: {:.6g}, lanczos: {:.6g}, ratio: {:.3f}}}\n",
      sim->critical_dt(), tight ? "lanczos" : "bound", bound, lanczos, lanczos / bound);
  printed << out.str();
}

}  // namespace dhpd
