// Scene reader: a full valid scene, defaults, command-line overrides and the resolved-YAML round
// trip. The refused scenes are in test_scene_errors.cpp.
#include <gtest/gtest.h>

#include "engine/base/errors.hpp"
#include "tests/support/scene_samples.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {
namespace {

using samples::kFullScene;
using samples::kMinimal;
using samples::kShapeScene2D;
using samples::kShapeScene3D;

const std::string kBox3 = "{shape: box, min: [0, 0, 0], max: [1, 1, 1], spacing: 0.1, material: g}";

TEST(Scene, FullSceneParsesIntoTheExpectedValues) {
  const Scene s = parse_scene(kFullScene, "full.yaml");
  EXPECT_EQ(s.name, "plate-ringing");
  EXPECT_EQ(s.dimension, 2);
  EXPECT_EQ(s.plane, PlaneMode::Strain);
  EXPECT_DOUBLE_EQ(s.thickness, 0.002);
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "glass");
  EXPECT_DOUBLE_EQ(s.materials[0].law.E, 72.0e9);
  EXPECT_DOUBLE_EQ(s.materials[1].law.G0, 1.0e4);
  EXPECT_EQ(s.materials[1].where.line, 7);
  EXPECT_EQ(s.materials[1].where.path, "materials.steel");
  ASSERT_EQ(s.body.size(), 2u);
  EXPECT_DOUBLE_EQ(s.body[1].shape.bounds(2).min[0], 0.1);
  EXPECT_DOUBLE_EQ(s.body[1].shape.bounds(2).max[1], 0.04);
  EXPECT_DOUBLE_EQ(s.body[1].shape.bounds(2).max[2], 0.0);
  EXPECT_DOUBLE_EQ(s.body[1].spacing, 0.0005);
  EXPECT_EQ(s.body[1].material, "steel");
  EXPECT_EQ(s.body[1].where.line, 14);
  EXPECT_EQ(s.body[1].where.path, "body.1");
  EXPECT_DOUBLE_EQ(s.horizon_factor, 4.0);
  EXPECT_EQ(s.model, ForceModel::ConstantHorizon);
  EXPECT_EQ(s.partial_volume, PartialVolume::Linear);
  ASSERT_EQ(s.cracks.size(), 1u);
  EXPECT_EQ(s.cracks[0].crack.points[1], (Vec3{0.05, 0.02, 0.0}));
  ASSERT_EQ(s.no_fail.size(), 1u);
  EXPECT_DOUBLE_EQ(s.no_fail[0].shape.bounds(2).min[0], 0.09);
  ASSERT_EQ(s.initial_conditions.size(), 1u);
  const InitialCondition& ic = s.initial_conditions[0].ic;
  EXPECT_EQ(ic.velocity, (Vec3{1.0, 0.0, 0.0}));
  EXPECT_FALSE(ic.displacement.has_value());
  EXPECT_EQ(ic.strain, (Vec3{1e-4, 0.0, 0.0}));
  EXPECT_EQ(ic.origin, (Vec3{0.05, 0.02, 0.0}));  // centre of the region by default
  EXPECT_EQ(ic.gaussian_width, 0.01);
  EXPECT_EQ(ic.gaussian_center, (Vec3{0.05, 0.02, 0.0}));
  ASSERT_EQ(s.boundary_conditions.size(), 3u);
  EXPECT_EQ(s.boundary_conditions[0].bc.kind, BoundaryCondition::Kind::Fixed);
  const BoundaryCondition& pull = s.boundary_conditions[1].bc;
  EXPECT_EQ(pull.kind, BoundaryCondition::Kind::Velocity);
  EXPECT_EQ(pull.velocity[0], 0.1);
  EXPECT_FALSE(pull.velocity[1].has_value());
  const BoundaryCondition& load = s.boundary_conditions[2].bc;
  EXPECT_EQ(load.kind, BoundaryCondition::Kind::Traction);
  EXPECT_EQ(load.traction, (Vec3{0.0, 1.0e6, 0.0}));
  EXPECT_EQ(load.normal_axis, 1);
  EXPECT_EQ(s.boundary_conditions[2].where.path, "boundary_conditions.2");
  EXPECT_TRUE(s.effects.fracture);
  EXPECT_EQ(s.time.end, 1.0e-5);
  EXPECT_FALSE(s.time.steps.has_value());
  EXPECT_DOUBLE_EQ(s.time.safety, 0.5);
  EXPECT_EQ(s.time.dt, 1.0e-8);
  EXPECT_EQ(s.time.where.line, 36);
  EXPECT_EQ(s.output.directory, "results");
  EXPECT_EQ(s.output.every, 100);
  EXPECT_FALSE(s.output.frames.has_value());
  EXPECT_EQ(s.output.fields, (std::vector<std::string>{"strain_energy_density", "bond_count"}));
  EXPECT_EQ(s.output.history_every, 5);
}

TEST(Scene, DefaultsAreFilledIn) {
  const Scene s = parse_scene(kMinimal, "min.yaml");
  EXPECT_EQ(s.plane, PlaneMode::Stress);
  EXPECT_DOUBLE_EQ(s.thickness, 1.0);
  EXPECT_DOUBLE_EQ(s.horizon_factor, 3.015);
  EXPECT_EQ(s.model, ForceModel::DualHorizon);
  EXPECT_EQ(s.partial_volume, PartialVolume::None);
  EXPECT_FALSE(s.effects.fracture);
  EXPECT_DOUBLE_EQ(s.time.safety, 0.5);
  EXPECT_EQ(s.time.stable_step, StableStepEstimate::Lanczos);
  EXPECT_EQ(s.output.frames, 20);
  EXPECT_FALSE(s.output.every.has_value());
  EXPECT_EQ(s.output.directory, "out");
  EXPECT_EQ(s.output.history_every, 10);
  EXPECT_EQ(s.output.compression, "lz4");
}

TEST(SceneOverrides, ReplaceListItemValues) {
  const Scene s = parse_scene(kFullScene, "full.yaml", {{"body.1.spacing", "2.5e-4"}});
  EXPECT_DOUBLE_EQ(s.body[1].spacing, 2.5e-4);
  EXPECT_DOUBLE_EQ(s.body[0].spacing, 0.001);
}

TEST(SceneOverrides, CreateMissingKeysAndWholeValues) {
  const Scene s = parse_scene(kMinimal, "min.yaml",
                              {{"effects.fracture", "true"},
                               {"time.dt", "1e-8"},
                               {"output", "{every: 7, fields: [bond_count]}"},
                               {"body.0.max", "[2, 3]"}});
  EXPECT_TRUE(s.effects.fracture);
  EXPECT_EQ(s.time.dt, 1e-8);
  EXPECT_EQ(s.time.end, 1.0);
  EXPECT_EQ(s.output.every, 7);
  EXPECT_EQ(s.output.fields, std::vector<std::string>{"bond_count"});
  EXPECT_DOUBLE_EQ(s.body[0].shape.bounds(2).max[1], 3.0);
}

TEST(SceneOverrides, FillAnEmptyMapOfTheFile) {
  const Scene s =
      parse_scene(std::string(kMinimal) + "effects:\n", "min.yaml", {{"effects.fracture", "true"}});
  EXPECT_TRUE(s.effects.fracture);
}

TEST(SceneOverrides, LaterOverrideWinsAndWholeMapReplaced) {
  const Scene s = parse_scene(kFullScene, "full.yaml",
                              {{"effects", "{fracture: false}"},
                               {"model", "dual-horizon"},
                               {"model", "classical-variable"}});
  EXPECT_FALSE(s.effects.fracture);
  EXPECT_EQ(s.model, ForceModel::ClassicalVariable);
}

TEST(Scene, ThreeDimensionalCrackIsAnyPlanarPolygon) {
  const std::string text =
      "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n"
      "  - {shape: box, min: [0, 0, 0], max: [1, 1, 1], spacing: 0.1, material: g}\n"
      "cracks:\n  - [[0, 0, 0.5], [1, 0, 0.5], [1, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5, 1, 0.5], "
      "[0, 1, 0.5]]\ntime: {steps: 1}\n";
  const Scene s = parse_scene(text, "l.yaml");
  ASSERT_EQ(s.cracks.size(), 1u);
  EXPECT_EQ(s.cracks[0].crack.points.size(), 6u);
}

TEST(SceneOverrides, StepsReplaceEndAndEveryReplacesFrames) {
  const std::string text = std::string(kMinimal) + "output: {frames: 4}\n";
  const Scene s = parse_scene(text, "min.yaml", {{"time.steps", "5"}, {"output.every", "2"}});
  EXPECT_EQ(s.time.steps, 5);
  EXPECT_FALSE(s.time.end.has_value());
  EXPECT_EQ(s.output.every, 2);
  EXPECT_FALSE(s.output.frames.has_value());
  const Scene back = parse_scene(text, "min.yaml", {{"time.steps", "5"}, {"time.end", "0.5"}});
  EXPECT_EQ(back.time.end, 0.5);
  EXPECT_FALSE(back.time.steps.has_value());
  // In the file itself, both of a pair stay an error.
  EXPECT_THROW(parse_scene(std::string(kMinimal) + "output: {frames: 4, every: 2}\n", "min.yaml"),
               InputError);
}

TEST(SceneOverrides, ParseOverrideSplitsAtFirstEquals) {
  const Override o = parse_override("output.directory=a=b");
  EXPECT_EQ(o.path, "output.directory");
  EXPECT_EQ(o.value, "a=b");
  EXPECT_THROW(parse_override("time.end"), InputError);
}

TEST(SceneFail, FormatsLocationAndAllowedList) {
  try {
    fail(Location{"a.yaml", 3, "body.1.spacing"}, "too big", "> 0");
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "a.yaml:3: body.1.spacing: too big (allowed: > 0)");
  }
  try {
    fail(Location{"--set", 0, "time.dt"}, "above the stable step");
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--set time.dt: above the stable step");
  }
}

void expect_same_shape(const geometry::Shape& a, const geometry::Shape& b) {
  EXPECT_TRUE(a == b);
}

void expect_same_materials_and_body(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_EQ(a.materials[i].law.E, b.materials[i].law.E);
    EXPECT_EQ(a.materials[i].law.rho, b.materials[i].law.rho);
    EXPECT_EQ(a.materials[i].law.G0, b.materials[i].law.G0);
  }
  ASSERT_EQ(a.body.size(), b.body.size());
  for (std::size_t i = 0; i < a.body.size(); ++i) {
    expect_same_shape(a.body[i].shape, b.body[i].shape);
    EXPECT_EQ(a.body[i].spacing, b.body[i].spacing);
    EXPECT_EQ(a.body[i].material, b.body[i].material);
  }
  ASSERT_EQ(a.material_regions.size(), b.material_regions.size());
  for (std::size_t i = 0; i < a.material_regions.size(); ++i) {
    expect_same_shape(a.material_regions[i].region, b.material_regions[i].region);
    EXPECT_EQ(a.material_regions[i].material, b.material_regions[i].material);
  }
}

void expect_same_regions(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.cracks.size(), b.cracks.size());
  for (std::size_t i = 0; i < a.cracks.size(); ++i)
    EXPECT_EQ(a.cracks[i].crack.points, b.cracks[i].crack.points);
  ASSERT_EQ(a.no_fail.size(), b.no_fail.size());
  for (std::size_t i = 0; i < a.no_fail.size(); ++i)
    expect_same_shape(a.no_fail[i].shape, b.no_fail[i].shape);
  ASSERT_EQ(a.initial_conditions.size(), b.initial_conditions.size());
  for (std::size_t i = 0; i < a.initial_conditions.size(); ++i) {
    const auto &x = a.initial_conditions[i].ic, &y = b.initial_conditions[i].ic;
    expect_same_shape(x.region, y.region);
    EXPECT_EQ(x.velocity, y.velocity);
    EXPECT_EQ(x.displacement, y.displacement);
    EXPECT_EQ(x.strain, y.strain);
    EXPECT_EQ(x.origin, y.origin);
    EXPECT_EQ(x.gaussian_width, y.gaussian_width);
    EXPECT_EQ(x.gaussian_center, y.gaussian_center);
  }
  ASSERT_EQ(a.boundary_conditions.size(), b.boundary_conditions.size());
  for (std::size_t i = 0; i < a.boundary_conditions.size(); ++i) {
    const auto &x = a.boundary_conditions[i].bc, &y = b.boundary_conditions[i].bc;
    EXPECT_EQ(x.kind, y.kind);
    expect_same_shape(x.region, y.region);
    EXPECT_EQ(x.velocity, y.velocity);
    EXPECT_EQ(x.traction, y.traction);
    EXPECT_EQ(x.normal_axis, y.normal_axis);
  }
}

/// Field-by-field equality of two scenes, ignoring source locations.
void expect_same_scene(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.dimension, b.dimension);
  EXPECT_EQ(a.plane, b.plane);
  EXPECT_EQ(a.thickness, b.thickness);
  EXPECT_EQ(a.area, b.area);
  expect_same_materials_and_body(a, b);
  EXPECT_EQ(a.horizon_factor, b.horizon_factor);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.partial_volume, b.partial_volume);
  expect_same_regions(a, b);
  EXPECT_EQ(a.effects.fracture, b.effects.fracture);
  ASSERT_EQ(a.refinement.has_value(), b.refinement.has_value());
  if (a.refinement) {
    const auto &ra = a.refinement->settings, &rb = b.refinement->settings;
    EXPECT_EQ(ra.trigger.damage, rb.trigger.damage);
    EXPECT_EQ(ra.trigger.energy, rb.trigger.energy);
    EXPECT_EQ(ra.trigger.stretch, rb.trigger.stretch);
    EXPECT_EQ(ra.buffer, rb.buffer);
    EXPECT_EQ(ra.max_level, rb.max_level);
    EXPECT_EQ(ra.check_every, rb.check_every);
    EXPECT_EQ(ra.zones.size(), rb.zones.size());
    EXPECT_EQ(ra.within.size(), rb.within.size());
    EXPECT_EQ(ra.mapping, rb.mapping);
  }
  EXPECT_EQ(a.time.end, b.time.end);
  EXPECT_EQ(a.time.steps, b.time.steps);
  EXPECT_EQ(a.time.safety, b.time.safety);
  EXPECT_EQ(a.time.dt, b.time.dt);
  EXPECT_EQ(a.output.directory, b.output.directory);
  EXPECT_EQ(a.output.every, b.output.every);
  EXPECT_EQ(a.output.frames, b.output.frames);
  EXPECT_EQ(a.output.fields, b.output.fields);
  EXPECT_EQ(a.output.history_every, b.output.history_every);
}

class ResolvedRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(ResolvedRoundTrip, ReadsBackIntoTheSameScene) {
  const Scene first = parse_scene(GetParam(), "in.yaml");
  const std::string text = resolved_yaml(first);
  SCOPED_TRACE(text);
  const Scene second = parse_scene(text, "resolved.yaml");
  expect_same_scene(first, second);
  EXPECT_EQ(resolved_yaml(second), text);
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ResolvedRoundTrip,
    ::testing::Values(
        std::string(kFullScene), std::string(kMinimal),
        std::string("name: bar\ndimension: 1\narea: 1e-4\nmaterials: {al: {E: 7e10, rho: 2700}}\n"
                    "body: [{shape: box, min: [0], max: [1], spacing: 0.01, material: al}]\n"
                    "initial_conditions: [{region: {shape: box, min: [0], max: [0.5]}, "
                    "displacement: [1e-3], origin: [0.1]}]\n"
                    "time: {steps: 1000}\noutput: {frames: 3}\n"),
        "name: cube\ndimension: 3\nmaterials: {g: {E: 1e9, rho: 1000, nu: 0.25, G0: 2}}\nbody:\n"
        "  - " +
            kBox3 +
            "\ncracks: [[[0, 0, 0.5], [1, 0, 0.5], [1, 1, 0.5], [0, 1, 0.5]]]\n"
            "boundary_conditions:\n  - {region: {shape: box, min: [0, 0, 0], max: [1, 1, 0.1]}, "
            "velocity: {y: -0.5, z: 0.25}}\n  - {region: {shape: box, min: [0, 0, 0.9], "
            "max: [1, 1, 1]}, traction: [0, 0, 3e5], normal: z}\n"
            "effects: {fracture: true}\ntime: {end: 3e-6}\n",
        std::string(kShapeScene2D), std::string(kShapeScene3D),
        std::string(kMinimal) +
            "effects:\n  fracture: true\n  refinement:\n    trigger: {damage: 0.05, stretch: 0.8}\n"
            "    buffer: 1.5\n    max_level: 2\n    check_every: 5\n    mapping: linear\n"
            "    zones: [{shape: disk, center: [0.5, 0.5], radius: 0.2}]\n"
            "    within: [{shape: box, min: [0, 0], max: [0.7, 1]}]\n",
        std::string(kMinimal) + "effects: {refinement: false}\n"));

TEST(SceneResolved, FillsDefaultsAndImpliedPoissonRatio) {
  const std::string text = resolved_yaml(parse_scene(kMinimal, "min.yaml"));
  EXPECT_NE(text.find("plane: stress"), std::string::npos) << text;
  EXPECT_NE(text.find("nu: 0.3333333333333333"), std::string::npos) << text;
  EXPECT_NE(text.find("frames: 20"), std::string::npos) << text;
  EXPECT_NE(text.find("history_every: 10"), std::string::npos) << text;
  EXPECT_EQ(text.find("area:"), std::string::npos) << text;
}

}  // namespace
}  // namespace dhpd::scene
