// Prescribed motion over time (docs/theory.md §11): ramps and tables in dynamics and statics, and
// the tables a scene refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/physics/loads.hpp"
#include "tests/support/statics.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

/// A 1 m bar of E = ρ = 1, its left three points clamped, its right three held by `right`.
std::string driven_bar(const std::string& right, const std::string& solver) {
  return "name: bar\ndimension: 1\narea: 1.0\nmaterials:\n  m: {E: 1.0, rho: 1.0}\nbody:\n"
         "  - {shape: box, min: [0.0], max: [1.0], spacing: 0.01, material: m}\n"
         "boundary_conditions:\n"
         "  - {region: {shape: box, min: [0.0], max: [0.03]}, fixed: true}\n"
         "  - {region: {shape: box, min: [0.97], max: [1.0]}, " +
         right + "}\n" + solver;
}

// Dynamics: a displacement ramped over time is where the function says at the end of every step
// (each step's velocity lands on it), and a tabulated velocity holds the particles at its value
// at the middle of each step.
TEST(TimeFunctions, HeldComponentsFollowTheirFunctionsInDynamics) {
  const auto scene = scene::parse_scene(
      driven_bar("displacement: {x: {ramp: 1.0, to: 1.0e-4}}", "time: {steps: 1}\n"), "r.yaml");
  auto sim = scene::build_simulation(scene);
  const auto& f = scene.boundary_conditions[1].bc.in_time[0];
  const auto held = select(sim->particles(), scene.boundary_conditions[1].bc.region);
  double worst = 0.0;
  for (int k = 0; k < 400; ++k) {
    sim->step();
    for (const auto i : held)
      worst = std::max(worst, std::abs(sim->particles().displacement[0][i] - f.at(sim->time())));
  }
  std::printf("ramped displacement: largest |u − f(t)| = %.2e m over %.3g s\n", worst, sim->time());
  EXPECT_GT(sim->time(), 1.0);
  EXPECT_LT(worst, 1e-15);
  sim->check_stable(sim->energies());  // the supports' work, acceleration included, is counted
  const auto table = scene::parse_scene(
      driven_bar("velocity: {x: {table: [[0, 0], [0.5, 1.0e-3], [1.5, -1.0e-3]]}}",
                 "time: {steps: 1}\n"),
      "v.yaml");
  sim = scene::build_simulation(table);
  const auto& g = table.boundary_conditions[1].bc.in_time[0];
  worst = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double middle = sim->time() + 0.5 * sim->dt();
    sim->step();
    for (const auto i : held)
      worst = std::max(worst, std::abs(sim->particles().velocity[0][i] - g.at(middle)));
  }
  EXPECT_LT(worst, 1e-15);
  sim->check_stable(sim->energies());
}

// Statics: a tabulated displacement is the function's value at the load factor: out to 1e-4 at
// λ = 0.5 and back to 0 at λ = 1, where the elastic bar is at rest again.
TEST(TimeFunctions, StaticLoadStepsTakeTheFunctionAtTheLoadFactor) {
  auto sim = scene::build_simulation(scene::parse_scene(
      driven_bar("displacement: {x: {table: [[0, 0], [0.5, 1.0e-4], [1, 0]]}}",
                 "solver: {type: static, tolerance: 1.0e-9}\ntime: {steps: 2}\n"),
      "s.yaml"));
  const auto largest = [&] {
    double u = 0.0;
    for (const double v : sim->particles().displacement[0]) u = std::max(u, std::abs(v));
    return u;
  };
  sim->step();
  EXPECT_DOUBLE_EQ(largest(), 1.0e-4);
  sim->step();
  EXPECT_LT(largest(), 1e-12);
}

// Bad input: tables whose times do not increase, or whose file rows are not numbers.
TEST(TimeFunctions, SceneRefusesBadTables) {
  const auto refused = [](const std::string& right, const std::string& expected) {
    try {
      scene::parse_scene(driven_bar(right, "time: {steps: 1}\n"), "t.yaml");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("displacement: {x: {table: [[0, 0], [0.2, 1.0], [0.1, 2.0]]}}",
          "t.yaml:10: boundary_conditions.1.displacement.x.table: the times must increase: row 3 "
          "has t = 0.1 after t = 0.2");
  refused("displacement: {x: {ramp: 0.0, to: 1.0}}", "displacement.x.ramp");
  refused("displacement: {x: {ramp: 1.0, to: 1.0, table: [[0, 1]]}}", "not both");
  refused("displacement: {x: {table: missing_table.csv}}", "cannot open the table file");
  refused("velocity: {x: {table: []}}", "the table has no row");
}

}  // namespace
}  // namespace dhpd
