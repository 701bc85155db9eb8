// `model: multi-horizon` in a scene (docs/scenes.md; docs/theory.md §24): the CMES 2019 bar
// builds with interaction horizons at its two interfaces, and what the model cannot mean is
// refused at its key: another dimension, a state-based family, refinement, statics, a scene
// without a refinement zone.
#include <gtest/gtest.h>

#include <string>

#include "engine/base/errors.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

/// A 20 mm bar: 0.1 mm on the left half, 0.4 mm on the right, `model` and `extra` as given.
std::string bar(const std::string& model, const std::string& extra = "",
                const std::string& right = "0.0004") {
  return "name: bar\ndimension: 1\narea: 1.0e-6\nmaterials:\n  steel: {E: 200.0e9, rho: 8000}\n"
         "body:\n  - {shape: box, min: [0.0], max: [0.01], spacing: 0.0001, material: steel}\n"
         "  - {shape: box, min: [0.01], max: [0.02], spacing: " +
         right +
         ", material: steel}\n"
         "horizon: {factor: 3.015}\npartial_volume: linear\nmodel: " +
         model + "\n" + extra + "time: {steps: 10}\n";
}

void refused(const std::string& text, const std::string& expected) {
  try {
    scene::build_simulation(scene::parse_scene(text, "bar.yaml"));
    ADD_FAILURE() << "accepted: " << expected;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(MultiHorizonScene, TheBarBuildsWithInteractionHorizonsAtItsInterface) {
  auto sim = scene::build_simulation(scene::parse_scene(bar("multi-horizon"), "bar.yaml"));
  EXPECT_EQ(sim->setup().model, ForceModel::MultiHorizon);
  sim->run_steps(10);
  EXPECT_TRUE(std::isfinite(sim->particles().velocity[0][0]));
}

TEST(MultiHorizonScene, WhatTheModelCannotMeanIsRefusedAtItsKey) {
  refused(bar("multi-horizon", "", "0.0001"),
          "bar.yaml:11: model: model multi-horizon needs a refinement zone");
  refused(bar("{family: correspondence, horizon: multi-horizon}"),
          "model.horizon: multi-horizon is offered for the bond-based and ordinary state-based");
  refused(bar("{family: ordinary-state, horizon: multi-horizon, surface_correction: true}"),
          "model.surface_correction: multi-horizon's α already carries");
  refused(bar("multi-horizon", "effects: {refinement: true}\n"),
          "effects.refinement: refinement is not offered with model multi-horizon");
  refused(bar("multi-horizon", "solver: static\n"),
          "solver: the multi-horizon model's pair forces are not equal and opposite");
  const std::string plate =
      "name: plate\ndimension: 2\nplane: stress\nthickness: 0.001\nmaterials:\n"
      "  glass: {E: 72.0e9, rho: 2440}\nbody:\n"
      "  - {shape: box, min: [0, 0], max: [0.01, 0.01], spacing: 0.001, material: glass}\n"
      "model: multi-horizon\ntime: {steps: 1}\n";
  refused(plate, "bar.yaml:9: model: multi-horizon is defined in 1D only (this scene is 2D)");
}

}  // namespace
}  // namespace dhpd
