// Reading `solver` (docs/scenes.md, `solver`; docs/theory.md §22): `dynamic` (explicit time
// stepping, the default) or `static` (adaptive dynamic relaxation, one load step per time.steps),
// and what a static run refuses.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

const std::vector<std::string> kSolverKeys{"type",   "tolerance",        "max_iterations",
                                           "safety", "max_break_rounds", "trace_every"};

StaticSolver read_static_settings(const MapView& map) {
  StaticSolver solver;
  if (const auto tol = map.get("tolerance")) {
    solver.tolerance = positive_number(*tol);
    if (solver.tolerance >= 1.0)
      tol->fail(fmt::format("tolerance is a fraction of the load, got {}", tol->text()),
                "0 < tolerance < 1 (default 1e-6)");
  }
  if (const auto tol = map.get("round_tolerance")) {
    solver.round_tolerance = positive_number(*tol);
    if (solver.round_tolerance >= 1.0)
      tol->fail(fmt::format("round_tolerance is a fraction of the load, got {}", tol->text()),
                "0 < round_tolerance < 1 (default 1e-3)");
  }
  if (const auto n = map.get("max_iterations")) solver.max_iterations = positive_integer(*n);
  if (const auto safety = map.get("safety")) solver.safety = safety_factor(*safety);
  if (const auto rounds = map.get("max_break_rounds")) {
    const auto n = positive_integer(*rounds);
    if (n > 1000000) rounds->fail(fmt::format("{} rounds", n), "1 to 1000000 (default 100000)");
    solver.max_break_rounds = static_cast<int>(n);
  }
  if (const auto every = map.get("trace_every")) {
    solver.trace_every = every->integer();
    if (solver.trace_every < 0)
      every->fail(fmt::format("trace_every must be >= 0, got {}", solver.trace_every),
                  ">= 0 (iterations between samples of relaxation.csv; 0: each relaxation's end)");
  }
  return solver;
}

/// The first of `conditions` that is a velocity condition (static runs hold displacements).
void refuse_velocity_conditions(const MapView& top, const Scene& s) {
  for (std::size_t k = 0; k < s.boundary_conditions.size(); ++k)
    if (s.boundary_conditions[k].bc.kind == BoundaryCondition::Kind::Velocity) {
      const auto list = top.require("boundary_conditions").list();
      MapView(list[k], {})
          .require("velocity")
          .fail("a static run holds displacements, not velocities",
                "displacement: {x: ...}, fixed: true or traction (or solver: dynamic)");
    }
  for (std::size_t k = 0; k < s.initial_conditions.size(); ++k)
    if (s.initial_conditions[k].ic.velocity) {
      const auto list = top.require("initial_conditions").list();
      MapView(list[k], {})
          .require("velocity")
          .fail("a static state is at rest: an initial velocity means nothing to it",
                "displacement or strain (or solver: dynamic)");
    }
}

}  // namespace

void read_solver(const MapView& top, Scene& s) {
  const auto solver = top.get("solver");
  if (!solver) return;
  const std::vector<std::string> kinds{"dynamic", "static"};
  if (!solver->node().IsMap()) {
    if (solver->choice(kinds, "solver") == 1) s.statics = StaticSolver{};
    s.solver_where = solver->where();
    return;
  }
  const MapView map(*solver, kSolverKeys);
  const bool is_static = map.require("type").choice(kinds, "solver type") == 1;
  s.solver_where = solver->where();
  if (!is_static) {
    if (map.entries().size() > 1)
      map.entries()[1].second.fail("the dynamic solver takes no settings here (see time)",
                                   "type: dynamic, or type: static with its settings");
    return;
  }
  s.statics = read_static_settings(map);
}

void check_static_solver(const MapView& top, const Scene& s) {
  if (!s.statics) return;
  const MapView time(top.require("time"), {});
  if (const auto end = time.get("end"))
    end->fail("a static run counts load steps, not seconds", "time.steps (the load steps)");
  if (const auto dt = time.get("dt"))
    dt->fail("a static run has no time step: its load steps are time.steps",
             "leave dt out (or solver: dynamic)");
  if (const auto multirate = time.get("multirate"); multirate && *s.time.multirate)
    multirate->fail("time levels are a dynamic scheme", "false (or solver: dynamic)");
  if (!conserves_momentum(s.model))
    fail(s.solver_where,
         fmt::format("the {} model's pair forces are not equal and opposite, so its stiffness "
                     "is unsymmetric: the static solver's step estimate needs a symmetric one",
                     to_string(s.model)),
         "dual-horizon or constant-horizon models (or solver: dynamic)");
  refuse_velocity_conditions(top, s);
}

}  // namespace dhpd::scene::detail
