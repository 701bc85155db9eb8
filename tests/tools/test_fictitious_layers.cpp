// Fictitious boundary layers (docs/theory.md §23): the mirror rule's exact linear bar, the
// traction rule's force on a pulled plate, momentum and work in dynamics, and what a layer refuses.
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

using test::tension_plate;

/// A 1 m bar of E = 1 held by fictitious layers: clamped (mirror rule) on the left, moved by Δs
/// (mirror rule, u_f = 2Δs − u) on the right.
std::string layered_bar(const std::string& solver) {
  return "name: bar\ndimension: 1\narea: 1.0\nmaterials:\n  m: {E: 1.0, rho: 1.0}\nbody:\n"
         "  - {shape: box, min: [0.0], max: [1.0], spacing: 0.01, material: m}\n"
         "partial_volume: linear\nboundary_conditions:\n"
         "  - {fictitious_layer: x_min, fixed: true}\n"
         "  - {fictitious_layer: x_max, displacement: {x: 1.0e-4}}\n" +
         solver;
}

// The mirror rule holds the face itself at U*: the bar's displacement is Δs x/L, exactly (a
// linear field is its own odd mirror image about each face), and the layers are two horizons of
// mirrored points, flagged in the frames' field.
TEST(FictitiousLayers, MirrorRuleGivesTheExactLinearBar) {
  auto sim = scene::build_simulation(scene::parse_scene(
      layered_bar("solver: {type: static, tolerance: 1.0e-9}\ntime: {steps: 1}\n"), "b.yaml"));
  ASSERT_EQ(sim->fictitious_layers().size(), 2u);
  for (const auto& layer : sim->fictitious_layers()) EXPECT_EQ(layer.particle.size(), 6u);
  sim->step();
  const auto& p = sim->particles();
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    worst = std::max(worst, std::abs(p.displacement[0][i] - 1e-4 * p.reference_position[0][i]));
  std::printf("layered bar: largest |u − Δs x/L| = %.2e of Δs\n", worst / 1e-4);
  EXPECT_LT(worst, 1e-7 * 1e-4);
  const auto left = sim->layer_reaction(0), right = sim->layer_reaction(1);
  EXPECT_NEAR(right[0], 1e-4, 1e-8);  // E A ε with E = A = 1
  EXPECT_NEAR(left[0], -right[0], 1e-12);
}

// The traction rule: the 0.1 m plate pulled by 200 MPa through a layer on its right face and
// clamped by one on its left takes σ A from the layer, for the state-based families (bond-based
// PD's softer free edges take 16 % less: reported, not asserted), and the two layers' reactions
// balance.
TEST(FictitiousLayers, TractionRuleTransmitsTheTraction) {
  struct Case {
    const char* name;
    std::string model;
    double nu, factor, tolerance;
  };
  for (const auto& c : {Case{"ordinary", "{family: ordinary-state}", 0.25, 3.015, 0.03},
                        Case{"correspondence", "{family: correspondence}", 0.25, 2.015, 0.03},
                        Case{"bond-based", "dual-horizon", 1.0 / 3.0, 3.015, 0.2}}) {
    auto text = tension_plate("solver: {type: static, tolerance: 1.0e-8}\ntime: {steps: 1}\n",
                              c.model, c.nu);
    const auto from = text.find("  - region: {shape: box, min: [0, 0], max: [0.015, 0.1]}");
    const auto to = text.find("solver:");
    text.replace(from, to - from,
                 "  - {fictitious_layer: x_min, fixed: true}\n"
                 "  - {fictitious_layer: x_max, traction: [200.0e6, 0]}\n");
    text += "horizon: {factor: " + std::to_string(c.factor) + "}\n";
    auto sim = scene::build_simulation(scene::parse_scene(text, "plate.yaml"));
    sim->step();
    const auto left = sim->layer_reaction(0), right = sim->layer_reaction(1);
    const double applied = 200e6 * 0.1 * 0.01;
    std::printf("%s: layer force %.6g N (σA %.6g N, ratio %.4f)\n", c.name, right[0], applied,
                right[0] / applied);
    EXPECT_NEAR(right[0] / applied, 1.0, c.tolerance) << c.name;
    EXPECT_NEAR(left[0] / right[0], -1.0, 1e-6) << c.name;
  }
}

// Dynamics: the layers' particles move with the body's, so the body's momentum changes by the
// layers' reactions alone (trapezoidal in time, as velocity Verlet integrates forces) and their
// work keeps the energy ledger balanced (the guard lets the run through).
TEST(FictitiousLayers, MomentumChangesByTheLayersReactionsInDynamics) {
  auto sim =
      scene::build_simulation(scene::parse_scene(layered_bar("time: {steps: 1}\n"), "d.yaml"));
  const auto momentum = [&] {
    const auto& p = sim->particles();
    double m = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) m += p.density[i] * p.volume[i] * p.velocity[0][i];
    return m;
  };
  const auto reactions = [&] { return sim->layer_reaction(0)[0] + sim->layer_reaction(1)[0]; };
  const double start = momentum();
  double impulse = 0.0, last = reactions();
  for (int k = 0; k < 2000; ++k) {
    sim->step();
    const double now = reactions();
    impulse += 0.5 * sim->dt() * (last + now);
    last = now;
  }
  const auto e = sim->energies();
  sim->check_stable(e);
  const double initial = sim->energy_budget().initial;
  std::printf(
      "momentum change %.6e, impulse of the layers %.6e; strain + kinetic %.6e J, "
      "initial + work %.6e J\n",
      momentum() - start, impulse, e.strain + e.kinetic, initial + e.external_work);
  EXPECT_NEAR(e.strain + e.kinetic - e.verlet_correction, initial + e.external_work,
              1e-3 * initial);
  EXPECT_GT(std::abs(impulse), 1e-6);
  EXPECT_NEAR(momentum() - start, impulse, 1e-12 * std::abs(impulse) + 1e-15);
}

// Bad input: a layer on a face the code cannot mirror, with a region, a normal or a velocity.
TEST(FictitiousLayers, SceneRefusesWhatALayerCannotMean) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      scene::build_simulation(scene::parse_scene(text, "l.yaml"));
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  const std::string head = "name: l\ndimension: 2\nmaterials:\n  m: {E: 1.0e9, rho: 1000}\nbody:\n";
  const std::string square =
      "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.05, material: m}\n";
  const std::string tail = "time: {steps: 1}\n";
  refused(head +
              "  - {shape: disk, center: [0.5, 0.5], radius: 0.5, spacing: 0.05, material: m}\n" +
              "boundary_conditions:\n  - {fictitious_layer: x_max, fixed: true}\n" + tail,
          "boundary_conditions.0.fictitious_layer: the body's face at x = 1 is not flat within two "
          "horizon");
  refused(head + square +
              "  - {shape: box, min: [1, 0], max: [1.1, 0.5], spacing: 0.05, material: m}\n" +
              "boundary_conditions:\n  - {fictitious_layer: x_max, fixed: true}\n" + tail,
          "not flat within two horizons");
  refused(head + square +
              "boundary_conditions:\n  - {fictitious_layer: x_max, velocity: {x: 1.0}}\n" + tail,
          "boundary_conditions.0.velocity: a fictitious layer holds displacements or tractions");
  refused(head + square +
              "boundary_conditions:\n  - {fictitious_layer: x_max, traction: [1.0, 0], normal: "
              "y}\n" +
              tail,
          "boundary_conditions.0.normal: a fictitious layer's normal is its face's axis");
  refused(
      head + square + "boundary_conditions:\n  - {fictitious_layer: z_max, fixed: true}\n" + tail,
      "boundary_conditions.0.fictitious_layer");
  refused(head + square +
              "boundary_conditions:\n  - {fictitious_layer: x_max, fixed: true, region: {shape: "
              "box, min: [0, 0], max: [1, 1]}}\n" +
              tail,
          "a fictitious layer lies outside the body's face: it takes no region");
}

}  // namespace
}  // namespace dhpd
