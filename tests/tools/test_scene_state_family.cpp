// Scene reader, the state-based family (docs/scenes.md `model`, `nu`): what it accepts, and what
// it refuses with file:line: key.path, the value and what is allowed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {
namespace {

/// A 2D scene: line 4 the material, line 7 the model, line 8 time, line 9 effects.
std::string scene(const std::string& material = "{E: 1.0e9, rho: 1000, nu: 0.3}",
                  const std::string& model = "{family: ordinary-state, horizon: dual-horizon}",
                  const std::string& extra = "", int dimension = 2,
                  const std::string& time = "{end: 1.0}") {
  const std::string body =
      dimension == 1 ? "{shape: box, min: [0], max: [1], spacing: 0.1, material: g}"
                     : "{shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, material: g}";
  return "name: t\ndimension: " + std::to_string(dimension) + "\nmaterials:\n  g: " + material +
         "\nbody:\n  - " + body + "\nmodel: " + model + "\ntime: " + time + "\n" + extra;
}

TEST(StateFamilyScene, AcceptsFamilyHorizonInfluenceAndPoissonsRatio) {
  const auto s = parse_scene(scene("{E: 1.0e9, rho: 1000, nu: 0.35}",
                                   "{family: ordinary-state, horizon: classical-variable, "
                                   "influence: inverse-distance}"),
                             "good.yaml");
  EXPECT_EQ(s.family, ModelFamily::OrdinaryState);
  EXPECT_EQ(s.model, ForceModel::ClassicalVariable);
  EXPECT_EQ(s.influence, Influence::InverseDistance);
  EXPECT_DOUBLE_EQ(s.materials[0].law.nu, 0.35);
  EXPECT_TRUE(s.surface_correction);
  const auto off = parse_scene(
      scene("{E: 1.0e9, rho: 1000}", "{family: ordinary-state, surface_correction: false}"),
      "good.yaml");
  EXPECT_FALSE(off.surface_correction);
  const auto word = parse_scene(scene("{E: 1.0e9, rho: 1000}", "constant-horizon"), "good.yaml");
  EXPECT_EQ(word.family, ModelFamily::Bond);
  EXPECT_TRUE(std::isnan(word.materials[0].law.nu));
}

TEST(StateFamilyScene, RefusesWithLocation) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {scene("{E: 1.0e9, rho: 1000, nu: 0.5}"),
       "bad.yaml:4: materials.g.nu: Poisson's ratio must lie in (-1, 0.5), got 0.5 (allowed: -1 < "
       "nu < 0.5)"},
      {scene("{E: 1.0e9, rho: 1000, nu: -1.2}"),
       "bad.yaml:4: materials.g.nu: Poisson's ratio must lie in (-1, 0.5), got -1.2"},
      {scene("{E: 1.0e9, rho: 1000, nu: 0.2}", "{family: ordinary-state}", "", 1),
       "bad.yaml:4: materials.g.nu: a 1D bar has no Poisson effect"},
      {scene("{E: 1.0e9, rho: 1000, nu: 0.3}", "dual-horizon"),
       "bad.yaml:4: materials.g.nu: bond-based peridynamics fixes nu = 0.333333 in 2D plane "
       "stress, got 0.3"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: state}"), "bad.yaml:7: model.family: unknown"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: bond, surface_correction: true}"),
       "bad.yaml:7: model.surface_correction: surface_correction applies to the ordinary "
       "state-based family only"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: correspondence, horizon: classical-variable}"),
       "bad.yaml:7: model.horizon: the correspondence family is offered with dual"},
      {scene("{E: 1.0e9, rho: 1000, G0: 1.0, nu: 0.3}", "{family: correspondence}",
             "effects: {fracture: true}\n"),
       "bad.yaml:7: model.family: the correspondence family is elastic"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: bond, influence: constant}"),
       "bad.yaml:7: model.influence: influence applies to the state-based family only"},
      {scene("{E: 1.0e9, rho: 1000, nu: 0.3}", "{family: correspondence}",
             "effects: {refinement: true}\n"),
       "bad.yaml:9: effects.refinement: refinement is not available with the correspondence "
       "family"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: correspondence}", "interfaces: consistent\n"),
       "bad.yaml:9: interfaces: interfaces: consistent corrects the bond-based and ordinary "
       "state-based weights"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: ordinary-state}", "", 2,
             "{end: 1.0, stable_step: bound}"),
       "bad.yaml:8: time.stable_step: the per-particle bound is derived for bond-based PD"},
      {scene("{E: 1.0e9, rho: 1000}", "{family: ordinary-state}", "", 2,
             "{end: 1.0, multirate: true}"),
       "bad.yaml:8: time.multirate: the state-based family takes one global step"},
  };
  for (const auto& [yaml, expected] : bad) {
    try {
      parse_scene(yaml, "bad.yaml");
      ADD_FAILURE() << "accepted:\n" << yaml;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
          << "message:  " << e.what() << "\nexpected: " << expected;
    }
  }
}

}  // namespace
}  // namespace dhpd::scene
