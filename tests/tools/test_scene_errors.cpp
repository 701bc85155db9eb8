// Scene reader: a table of refused scenes, each with the exact file:line: key.path of its message.
#include <gtest/gtest.h>

#include <sstream>

#include "engine/base/errors.hpp"
#include "tests/support/scene_samples.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {
namespace {

using samples::kMinimal;

/// kMinimal with 1-based line `line` replaced by `text` (which may span several lines).
std::string replace_line(int line, const std::string& text) {
  std::istringstream in(kMinimal);
  std::string out, current;
  for (int n = 1; std::getline(in, current); ++n) out += (n == line ? text : current) + "\n";
  return out;
}
std::string plus(const std::string& text) {
  return std::string(kMinimal) + text + "\n";
}

struct BadScene {
  std::string name;
  std::string yaml;
  std::string expected;  ///< substring of the message, including "file:line: key.path:"
  std::vector<Override> overrides = {};
};

std::ostream& operator<<(std::ostream& os, const BadScene& c) {
  return os << c.name;
}

const std::string kBox3 = "{shape: box, min: [0, 0, 0], max: [1, 1, 1], spacing: 0.1, material: g}";

/// Lines 8–11 after kMinimal: fracture on and a measure block whose one tip is `tip`.
std::string measured(const std::string& tip = "{name: a, at: [0.5, 0.5], direction: [1, 0]}") {
  return "effects: {fracture: true}\nmeasure:\n  tips:\n    - " + tip + "\n";
}

/// no_fail regions r0..r<levels>, each the union of two aliases of the one before: a few lines
/// that stand for 2^levels boxes ("billion laughs").
std::string alias_ladder(int levels) {
  std::string text = "no_fail:\n  - &r0 {shape: box, min: [0, 0], max: [1, 1]}\n";
  for (int k = 1; k <= levels; ++k)
    text += "  - &r" + std::to_string(k) + " {shape: union, of: [*r" + std::to_string(k - 1) +
            ", *r" + std::to_string(k - 1) + "]}\n";
  return plus(text);
}

std::string repeated(const std::string& text, int times) {
  std::string out;
  for (int k = 0; k < times; ++k) out += text;
  return out;
}

/// A time.end of `depth` nested one-item lists.
std::string nested_lists(int depth) {
  return replace_line(
      7, "time: {end: " + std::string(depth, '[') + "1" + std::string(depth, ']') + "}");
}

const std::vector<BadScene> kBadScenes = {
    {"UnknownKeySuggestion",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, materail: glass}"),
     "bad.yaml:6: body.0.materail: unknown key 'materail', did you mean 'material'? (allowed: "
     "shape, min, max, spacing, mesh, point_size, material)"},
    {"UnknownTopLevelKey", replace_line(7, "tiem: {end: 1.0}"),
     "bad.yaml:7: tiem: unknown key 'tiem', did you mean 'time'?"},
    {"DuplicateKey", replace_line(4, "  glass:\n    E: 1.0e9\n    rho: 1000\n    E: 2.0e9"),
     "bad.yaml:7: materials.glass.E: duplicate key 'E' (first given on line 5)"},
    {"DuplicateTopLevelKey", plus("dimension: 3"),
     "bad.yaml:8: dimension: duplicate key 'dimension' (first given on line 2)"},
    {"YoungModulusZero", replace_line(4, "  glass: {E: 0, rho: 1000}"),
     "bad.yaml:4: materials.glass.E: E must be > 0, got 0 (allowed: > 0)"},
    {"DensityNegative", replace_line(4, "  glass:\n    E: 1.0e9\n    rho: -5"),
     "bad.yaml:6: materials.glass.rho: rho must be > 0, got -5 (allowed: > 0)"},
    {"FractureEnergyNegative", replace_line(4, "  glass: {E: 1.0e9, rho: 1000, G0: -1}"),
     "bad.yaml:4: materials.glass.G0: G0 must be >= 0, got -1"},
    {"EnergyAsString", replace_line(4, "  glass: {E: stiff, rho: 1000}"),
     "bad.yaml:4: materials.glass.E: expected a number, got 'stiff'"},
    {"QuotedNumber", replace_line(4, "  glass: {E: \"1e9\", rho: 1000}"),
     "bad.yaml:4: materials.glass.E: expected a number, got '1e9'"},
    {"SpacingZero",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0, material: glass}"),
     "bad.yaml:6: body.0.spacing: spacing must be > 0, got 0 (allowed: > 0)"},
    // Without the limit a mistyped spacing asked the lattice for 1e12 cells (and 1e300 overflowed
    // its integer cell counts).
    {"SpacingMakesTooManyCells",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 1e-6, material: glass}"),
     "bad.yaml:6: body.0.spacing: spacing 1e-06 makes about 1e+12 cells in this part, more than "
     "the 2147483647 particles a run can hold (allowed: spacing >= 2.16e-05)"},
    {"MeshSizeMakesTooManyCells",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], mesh: {size: 1e-300}, material: "
                  "glass}"),
     "bad.yaml:6: body.0.mesh.size: size 1e-300 makes about inf cells in this part"},
    {"SpacingLargerThanPart",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 0.5], spacing: 0.6, material: glass}"),
     "bad.yaml:6: body.0.spacing: spacing 0.6 is larger than the part's smallest extent 0.5"},
    {"MeshSizeLargerThanPart",
     replace_line(
         6, "  - {shape: box, min: [0, 0], max: [1, 0.5], mesh: {size: 0.6}, material: glass}"),
     "bad.yaml:6: body.0.mesh.size: size 0.6 is larger than the part's smallest extent 0.5"},
    {"MeshSizeZero",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], mesh: {size: 0}, material: glass}"),
     "bad.yaml:6: body.0.mesh.size: size must be > 0, got 0"},
    {"MeshAndSpacing",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, mesh: {size: 0.1}, "
                  "material: glass}"),
     "bad.yaml:6: body.0: give either spacing (a lattice) or mesh (a triangulation), not both"},
    {"NeitherMeshNorSpacing",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 1], material: glass}"),
     "bad.yaml:6: body.0: give the particle spacing, or mesh: {size: ...} for a mesh"},
    {"MeshGradingNegativeRate",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], material: glass,\n"
                  "     mesh: {size: 0.1, grading: {from: [0, 0], rate: -1}}}"),
     "bad.yaml:7: body.0.mesh.grading.rate: rate must be >= 0, got -1"},
    {"MeshIn1D",
     "name: t\ndimension: 1\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n"
     "  - {shape: box, min: [0], max: [1], mesh: {size: 0.1}, material: g}\ntime: {end: 1.0}\n",
     "bad.yaml:6: body.0.mesh: mesh parts are available in 2D and 3D only; this scene is 1D"},
    {"MissingPointsFile", replace_line(6, "  - {points_file: no-such-file.txt, material: glass}"),
     "bad.yaml:6: body.0.points_file: points file 'no-such-file.txt' does not exist"},
    {"PointsFileWithSpacing",
     replace_line(6, "  - {points_file: p.txt, spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.spacing: unknown key 'spacing'"},
    {"PointSizeOnALatticePart",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, point_size: "
                  "cell-side, material: glass}"),
     "bad.yaml:6: body.0.point_size: point_size applies to mesh and points-file parts; a "
     "lattice part's particle size is its spacing (allowed: mesh or points_file parts only)"},
    {"PointSizeUnknownWord",
     replace_line(6,
                  "  - {shape: box, min: [0, 0], max: [1, 1], mesh: {size: 0.2}, point_size: "
                  "cell_side, material: glass}"),
     "bad.yaml:6: body.0.point_size: unknown point_size 'cell_side', did you mean 'cell-side'? "
     "(allowed: equivalent-diameter, cell-side)"},
    {"BoxMaxBelowMin",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 0], spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.max: max must be greater than min on every axis, but on y"},
    {"PointOfWrongLength",
     replace_line(6, "  - {shape: box, min: [0, 0, 0], max: [1, 1], spacing: 0.1, material: g}"),
     "bad.yaml:6: body.0.min: expected a list of 2 numbers (one per axis), got 3 items"},
    {"UnknownShape",
     replace_line(6, "  - {shape: ball, min: [0, 0], max: [1, 1], spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.shape: unknown shape 'ball' (allowed: box, disk, polygon, half-space, "
     "union, difference, random-disks)"},
    {"ShapeOfOtherDimension",
     replace_line(6,
                  "  - {shape: sphere, center: [0, 0], radius: 1, spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.shape: shape 'sphere' exists only in 3D scenes; this scene has dimension "
     "2 (allowed: box, disk, polygon, half-space, union, difference, random-disks)"},
    {"ShapeKeyMisspelt",
     replace_line(6, "  - {shape: disk, center: [0, 0], raduis: 1, spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.raduis: unknown key 'raduis', did you mean 'radius'? (allowed: shape, "
     "center, radius, spacing, mesh, point_size, material)"},
    {"BoxKeyOnDisk",
     replace_line(6, "  - {shape: disk, min: [0, 0], radius: 1, spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.min: unknown key 'min' (allowed: shape, center, radius, spacing, "
     "mesh, point_size, material)"},
    {"RadiusZero",
     replace_line(6, "  - {shape: disk, center: [0, 0], radius: 0, spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.radius: radius must be > 0, got 0 (allowed: > 0)"},
    {"NestedRadiusNegative",
     replace_line(6,
                  "  - shape: difference\n    of:\n      - {shape: box, min: [0, 0], max: [1, "
                  "1]}\n      - {shape: disk, center: [0, 0], radius: -1}\n    spacing: 0.1\n"
                  "    material: glass"),
     "bad.yaml:9: body.0.of.1.radius: radius must be > 0, got -1 (allowed: > 0)"},
    {"HalfSpaceZeroNormal", plus("no_fail: [{shape: half-space, point: [0, 0], normal: [0, 0]}]"),
     "bad.yaml:8: no_fail.0.normal: normal must not be the zero vector"},
    {"CylinderZeroAxis",
     "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n  - {shape: "
     "cylinder, center: [0, 0, 0], axis: [0, 0, 0], radius: 1, height: 1, spacing: 0.1, "
     "material: g}\ntime: {end: 1.0}\n",
     "bad.yaml:6: body.0.axis: axis must not be the zero vector"},
    {"PolygonTwoPoints",
     replace_line(6,
                  "  - {shape: polygon, points: [[0, 0], [1, 0]], spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.points: a polygon needs at least 3 points, got 2 (allowed: >= 3 points)"},
    {"PolygonSelfIntersecting",
     replace_line(6,
                  "  - {shape: polygon, points: [[0, 0], [1, 1], [1, 0], [0, 1]], spacing: 0.1, "
                  "material: glass}"),
     "bad.yaml:6: body.0.points: the polygon intersects itself: edge 0 [0, 0]-[1, 1] and edge 2 "
     "[1, 0]-[0, 1] cross"},
    {"PolygonDuplicatePoint",
     replace_line(6,
                  "  - {shape: polygon, points: [[0, 0], [1, 0], [1, 0], [0, 1]], spacing: 0.1, "
                  "material: glass}"),
     "bad.yaml:6: body.0.points.2: point 2 repeats point 1 [1, 0]; give each corner once"},
    {"PolygonRepeatsFirstPoint",
     replace_line(6,
                  "  - {shape: polygon, points: [[0, 0], [1, 0], [0, 1], [0, 0]], spacing: 0.1, "
                  "material: glass}"),
     "bad.yaml:6: body.0.points.3: the last point repeats the first [0, 0]"},
    {"UnionWithoutOperands", plus("no_fail: [{shape: union, of: []}]"),
     "bad.yaml:8: no_fail.0.of: a union needs at least 1 operand, got 0"},
    {"DifferenceOfOne",
     plus("no_fail: [{shape: difference, of: [{shape: box, min: [0, 0], max: [1, 1]}]}]"),
     "bad.yaml:8: no_fail.0.of: a difference needs at least 2 operands, got 1"},
    {"UnboundedBodyPart",
     replace_line(6,
                  "  - {shape: half-space, point: [0, 0], normal: [1, 0], spacing: 0.1, "
                  "material: glass}"),
     "bad.yaml:6: body.0.shape: a body part must be bounded"},
    {"UnknownShapeInRegion", plus("no_fail: [{shape: circle, center: [0, 0], radius: 1}]"),
     "bad.yaml:8: no_fail.0.shape: unknown shape 'circle'"},
    {"MaterialRegionUnknownMaterial",
     plus("material_regions:\n  - region: {shape: disk, center: [0.5, 0.5], radius: 0.2}\n"
          "    material: glas"),
     "bad.yaml:10: material_regions.0.material: material 'glas' is not defined in materials, did "
     "you mean 'glass'?"},
    {"MaterialRegionWithoutRegion", plus("material_regions: [{material: glass}]"),
     "bad.yaml:8: material_regions.0: missing required key 'region'"},
    {"MaterialNotDefined",
     replace_line(6, "  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, material: glas}"),
     "bad.yaml:6: body.0.material: material 'glas' is not defined in materials, did you mean "
     "'glass'? (allowed: glass)"},
    {"HorizonFactorBelowOne", plus("horizon: {factor: 0.5}"),
     "bad.yaml:8: horizon.factor: the horizon factor (horizon / spacing) must be at least 1, got "
     "0.5"},
    {"HorizonNotAMap", plus("horizon: 3"), "bad.yaml:8: horizon: expected a map of keys, got '3'"},
    {"EmptyBody", replace_line(6, "  []"), "bad.yaml:5: body: the body needs at least one part"},
    {"BodyIsAMap", replace_line(6, "  shape: box"), "bad.yaml:5: body: expected a list, got a map"},
    {"EndTimeNegative", replace_line(7, "time: {end: -1}"),
     "bad.yaml:7: time.end: end must be > 0, got -1 (allowed: > 0)"},
    {"StepsNotInteger", replace_line(7, "time:\n  steps: 2.5"),
     "bad.yaml:8: time.steps: expected an integer, got '2.5'"},
    {"StepsZero", replace_line(7, "time: {steps: 0}"),
     "bad.yaml:7: time.steps: steps must be an integer > 0, got 0"},
    {"EndAndSteps", replace_line(7, "time: {end: 1, steps: 10}"),
     "bad.yaml:7: time: give either end or steps, not both (allowed: end, steps)"},
    {"SafetyAboveOne", replace_line(7, "time: {end: 1, safety: 1.5}"),
     "bad.yaml:7: time.safety: safety must lie in (0, 1], got 1.5 (allowed: 0 < safety <= 1)"},
    {"FixedStepZero", replace_line(7, "time: {end: 1, dt: 0}"),
     "bad.yaml:7: time.dt: dt must be > 0, got 0"},
    {"MissingTime", replace_line(7, "model: dual-horizon"),
     "bad.yaml:1: missing required key 'time'"},
    {"MaterialsAsList", replace_line(4, "  - {E: 1.0e9, rho: 1000}"),
     "bad.yaml:3: materials: expected a map of keys, got a list"},
    {"PoissonRatioIn3D",
     "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000, nu: 0.3}\nbody:\n  - " + kBox3 +
         "\ntime: {end: 1.0}\n",
     "bad.yaml:4: materials.g.nu: bond-based peridynamics fixes nu = 0.25 in 3D, got 0.3"},
    {"PlaneIn3D", "name: t\ndimension: 3\nplane: stress\n",
     "bad.yaml:3: plane: plane applies only to 2D scenes; this scene has dimension 3"},
    {"AreaIn2D", plus("area: 0.01"), "bad.yaml:8: area: area applies only to 1D scenes"},
    {"ThicknessZero", plus("thickness: 0"), "bad.yaml:8: thickness: thickness must be > 0, got 0"},
    {"DimensionFour", replace_line(2, "dimension: 4"),
     "bad.yaml:2: dimension: dimension must be 1, 2 or 3, got 4 (allowed: 1, 2, 3)"},
    {"UnknownModelWord", plus("model: dual-horizons"),
     "bad.yaml:8: model: unknown model 'dual-horizons', did you mean 'dual-horizon'? (allowed: "
     "dual-horizon, constant-horizon, classical-variable, multi-horizon)"},
    {"PartialVolumeUnknownWord", plus("partial_volume: exakt"),
     "bad.yaml:8: partial_volume: unknown partial_volume 'exakt', did you mean 'exact'? (allowed: "
     "none, linear, exact)"},
    {"CrackWithThreePoints2D", plus("cracks:\n  - [[0, 0.5], [0.5, 0.5], [0.7, 0.5]]"),
     "bad.yaml:9: cracks.0: expected a list of 2 end points"},
    {"CrackNotPlanar3D",
     "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n  - " + kBox3 +
         "\ncracks:\n  - [[0, 0, 0.5], [1, 0, 0.5], [1, 1, 0.5], [0, 1, 0.9]]\n",
     "bad.yaml:8: cracks.0: the corners of a 3D crack must lie in one plane"},
    {"CrackTwoCorners3D",
     "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n  - " + kBox3 +
         "\ncracks:\n  - [[0, 0, 0.5], [1, 0, 0.5]]\n",
     "bad.yaml:8: cracks.0: a 3D crack is a planar polygon of at least 3 corners"},
    {"CrackIn1D",
     "name: t\ndimension: 1\nmaterials: {g: {E: 1, rho: 1}}\n"
     "body: [{shape: box, min: [0], max: [1], spacing: 0.1, material: g}]\ncracks: []\n",
     "bad.yaml:5: cracks: cracks are not available in 1D scenes"},
    {"EveryAndFrames", plus("output:\n  every: 10\n  frames: 5"),
     "bad.yaml:8: output: give either every (steps between frames) or frames (count), not both"},
    {"BadFieldName", plus("output: {fields: [strain_energy_densty]}"),
     "bad.yaml:8: output.fields.0: unknown field 'strain_energy_densty', did you mean "
     "'strain_energy_density'? (allowed: force_density, no_fail, strain_energy_density"},
    {"FieldListedTwice", plus("output:\n  fields: [bond_count, bond_count]"),
     "bad.yaml:9: output.fields.1: field 'bond_count' is listed twice"},
    {"DefaultFieldListed", plus("output: {fields: [damage]}"),
     "bad.yaml:8: output.fields.0: field 'damage' is always written"},
    {"UnknownCompression", plus("output: {compression: gzip}"),
     "bad.yaml:8: output.compression: unknown compression 'gzip'"},
    {"HistoryEveryZero", plus("output: {history_every: 0}"),
     "bad.yaml:8: output.history_every: history_every must be an integer > 0, got 0"},
    {"VelocityAxisZIn2D",
     plus("boundary_conditions:\n  - region: {shape: box, min: [0, 0], max: [1, 1]}\n"
          "    velocity: {x: 0, z: 1}"),
     "bad.yaml:10: boundary_conditions.0.velocity.z: axis 'z' does not exist in a 2D scene "
     "(allowed: x, y)"},
    {"TractionWithoutNormal",
     plus("boundary_conditions:\n  - region: {shape: box, min: [0, 0], max: [1, 1]}\n"
          "    traction: [1, 0]"),
     "bad.yaml:9: boundary_conditions.0: missing required key 'normal'"},
    {"NormalWithoutTraction",
     plus("boundary_conditions:\n  - region: {shape: box, min: [0, 0], max: [1, 1]}\n"
          "    fixed: true\n    normal: x"),
     "bad.yaml:11: boundary_conditions.0.normal: normal is only used with traction"},
    {"FixedFalse",
     plus("boundary_conditions:\n  - {region: {shape: box, min: [0, 0], max: [1, 1]}, fixed: no}"),
     "bad.yaml:9: boundary_conditions.0.fixed: expected true or false, got 'no'"},
    {"TwoBoundaryKinds",
     plus("boundary_conditions:\n  - {region: {shape: box, min: [0, 0], max: [1, 1]}, fixed: true,"
          " velocity: {x: 1}}"),
     "bad.yaml:9: boundary_conditions.0: give only one of velocity, fixed, traction"},
    {"InitialConditionWithoutValues",
     plus("initial_conditions:\n  - {region: {shape: box, min: [0, 0], max: [1, 1]}}"),
     "bad.yaml:9: initial_conditions.0: give at least one of velocity, displacement, strain"},
    {"GaussianWidthZero",
     plus("initial_conditions:\n  - region: {shape: box, min: [0, 0], max: [1, 1]}\n"
          "    velocity: [0, 1]\n    gaussian: {center: [0.5, 0.5], width: 0}"),
     "bad.yaml:11: initial_conditions.0.gaussian.width: width must be > 0, got 0"},
    {"FractureWithoutG0",
     replace_line(4, "  glass: {E: 1.0e9, rho: 1000}\neffects: {fracture: true}"),
     "bad.yaml:4: materials.glass: G0 (fracture energy, J/m^2) is required when effects.fracture "
     "is true"},
    {"UnknownEffect", plus("effects: {refinment: false}"),
     "bad.yaml:8: effects.refinment: unknown key 'refinment', did you mean 'refinement'? "
     "(allowed: fracture, refinement)"},
    {"RefinementTriggerAboveOne", plus("effects:\n  refinement: {trigger: {damage: 1.5}}"),
     "bad.yaml:9: effects.refinement.trigger.damage: damage is a fraction, got 1.5 (a particle "
     "never reaches it) (allowed: 0 < value <= 1)"},
    {"RefinementNearCrackAlone", plus("effects:\n  refinement: {trigger: {near_crack: 2}}"),
     "bad.yaml:9: effects.refinement.trigger.near_crack: near_crack limits the stretch trigger, "
     "which is not given (allowed: stretch with it)"},
    {"RefinementNearPrecrackAlone",
     plus("effects:\n  refinement: {trigger: {stretch: 0.3, near_precrack: 2}}"),
     "bad.yaml:9: effects.refinement.trigger.near_precrack: near_precrack widens near_crack around "
     "pre-cracks, but near_crack is not given (allowed: near_crack (and stretch) with it)"},
    {"RefinementNearPrecrackNegative",
     plus("effects:\n  refinement: {trigger: {stretch: 0.3, near_crack: 1, near_precrack: -2}}"),
     "bad.yaml:9: effects.refinement.trigger.near_precrack: "},
    {"RefinementUnknownMapping", plus("effects:\n  refinement: {mapping: cubic}"),
     "bad.yaml:9: effects.refinement.mapping: "},
    {"RefinementUnknownKey", plus("effects:\n  refinement: {trigger: {damage: 0.1}, bufer: 1}"),
     "bad.yaml:9: effects.refinement.bufer: unknown key 'bufer', did you mean 'buffer'?"},
    {"RefinementUnknownTrigger", plus("effects:\n  refinement:\n    trigger: {damag: 0.1}"),
     "bad.yaml:10: effects.refinement.trigger.damag: unknown key 'damag', did you mean 'damage'?"},
    {"RefinementWithinNotARegion", plus("effects:\n  refinement: {within: [5]}"),
     "bad.yaml:9: effects.refinement.within.0: "},
    {"RefinementThresholdZero", plus("effects:\n  refinement: {trigger: {energy: 0}}"),
     "bad.yaml:9: effects.refinement.trigger.energy: energy must be > 0, got 0 (allowed: > 0)"},
    {"RefinementEmptyTrigger", plus("effects:\n  refinement: {trigger: {}}"),
     "bad.yaml:9: effects.refinement.trigger: trigger needs at least one threshold"},
    {"RefinementMaxLevelFraction",
     plus("effects:\n  refinement: {trigger: {damage: 0.1}, max_level: 1.5}"),
     "bad.yaml:9: effects.refinement.max_level:"},
    {"RefinementMaxLevelZero",
     plus("effects:\n  refinement: {trigger: {damage: 0.1}, max_level: 0}"),
     "bad.yaml:9: effects.refinement.max_level: max_level must be an integer > 0, got 0"},
    {"RefinementCheckEveryZero",
     plus("effects:\n  refinement: {trigger: {damage: 0.1}, check_every: 0}"),
     "bad.yaml:9: effects.refinement.check_every: check_every must be an integer > 0"},
    {"RefinementMappingWord",
     plus("effects:\n  refinement: {trigger: {damage: 0.1}, mapping: linar}"),
     "bad.yaml:9: effects.refinement.mapping: unknown mapping 'linar', did you mean 'linear'?"},
    {"InterfacesConsistentOnAMesh",
     replace_line(
         6, "  - {shape: box, min: [0, 0], max: [1, 1], mesh: {size: 0.2}, material: glass}") +
         "interfaces: consistent\n",
     "interfaces: consistent corrects the level jumps of lattice parts, but body.0"},
    {"RefinementOfMesh",
     replace_line(
         6, "  - {shape: box, min: [0, 0], max: [1, 1], mesh: {size: 0.2}, material: glass}") +
         "effects: {refinement: {trigger: {damage: 0.1}}}\n",
     "bad.yaml:8: effects.refinement: refinement splits lattice particles only, but body.0 is a "
     "mesh part (line 6)"},
    {"RefinementConstantHorizon",
     plus("model: constant-horizon\neffects: {refinement: {trigger: {damage: 0.1}}}"),
     "bad.yaml:9: effects.refinement: refinement needs per-particle horizons"},
    {"MeasureUnknownKey", plus(measured() + "  smothing: 3"),
     "bad.yaml:12: measure.smothing: unknown key 'smothing', did you mean 'smoothing'? (allowed: "
     "damage_threshold, every, smoothing, branch_separation, tips, published)"},
    {"MeasureThresholdAboveOne", plus(measured() + "  damage_threshold: 1.5"),
     "bad.yaml:12: measure.damage_threshold: damage_threshold must lie in (0, 1), got 1.5 "
     "(allowed: 0 < damage_threshold < 1)"},
    {"MeasureEveryZero", plus(measured() + "  every: 0"),
     "bad.yaml:12: measure.every: every must be an integer > 0, got 0 (allowed: integers >= 1)"},
    {"MeasureSmoothingFraction", plus(measured() + "  smoothing: 1.5"),
     "bad.yaml:12: measure.smoothing: expected an integer, got '1.5'"},
    {"MeasureBranchSeparationZero", plus(measured() + "  branch_separation: 0"),
     "bad.yaml:12: measure.branch_separation: branch_separation must be > 0, got 0"},
    {"MeasureEmptyTips", plus("effects: {fracture: true}\nmeasure:\n  tips: []"),
     "bad.yaml:10: measure.tips: give at least one notch tip (allowed: a list of {name: ..., at: "
     "[...], direction: [...]})"},
    {"MeasureWithoutTips", plus("effects: {fracture: true}\nmeasure: {every: 5}"),
     "bad.yaml:9: measure: missing required key 'tips'"},
    {"MeasureDuplicateTipName",
     plus(measured() + "    - {name: a, at: [0.2, 0.5], direction: [0, 1]}"),
     "bad.yaml:12: measure.tips.1.name: duplicate tip name 'a' (first given on line 11)"},
    {"MeasureTipNameWithComma", plus(measured("{name: 'a,b', at: [0.5, 0.5], direction: [1, 0]}")),
     "bad.yaml:11: measure.tips.0.name: tip name 'a,b' cannot be written as a CSV cell or "
     "column"},
    {"ProbeDuplicateName",
     plus("output:\n  probes:\n    - {name: P, at: [0.5, 0.5]}\n    - {name: P, at: [0.2, 0.5]}"),
     "bad.yaml:11: output.probes.1.name: duplicate probe name 'P' (first given on line 10)"},
    {"ProbeNameWithComma", plus("output:\n  probes:\n    - {name: 'a,b', at: [0.5, 0.5]}"),
     "bad.yaml:10: output.probes.0.name: probe name 'a,b' cannot be written as a CSV cell or "
     "column (allowed: letters, digits, '_', '.', '-')"},
    {"ProbeAtOfWrongDimension", plus("output:\n  probes:\n    - {name: P, at: [0.5, 0.5, 0]}"),
     "bad.yaml:10: output.probes.0.at: expected a list of 2 numbers (one per axis), got 3 items"},
    {"ProbeWithoutAt", plus("output:\n  probes:\n    - {name: P}"),
     "bad.yaml:10: output.probes.0: missing required key 'at'"},
    {"MeasureZeroDirection", plus(measured("{name: a, at: [0.5, 0.5], direction: [0, 0]}")),
     "bad.yaml:11: measure.tips.0.direction: direction must not be the zero vector"},
    {"MeasureTipWithThreeComponents",
     plus(measured("{name: a, at: [0.5, 0.5, 0], direction: [1, 0]}")),
     "bad.yaml:11: measure.tips.0.at: expected a list of 2 numbers (one per axis), got 3 items"},
    {"MeasureTipUnknownKey",
     plus(measured("{name: a, at: [0.5, 0.5], direction: [1, 0], dir: [1, 0]}")),
     "bad.yaml:11: measure.tips.0.dir: unknown key 'dir' (allowed: name, at, direction, front, "
     "region)"},
    {"MeasureTipOutsideItsRegion",
     plus(measured("{name: a, at: [0.5, 0.5], direction: [1, 0],\n"
                   "       region: {shape: half-space, point: [0, 0.6], normal: [0, -1]}}")),
     "bad.yaml:12: measure.tips.0.region: the notch tip [0.5, 0.5] lies outside its region "
     "(allowed: a region that holds the notch tip)"},
    {"MeasureFrontIn2D",
     plus(measured("{name: a, at: [0.5, 0.5], direction: [1, 0], front: [0, 1]}")),
     "bad.yaml:11: measure.tips.0.front: front is the notch front's direction of a 3D scene"},
    {"MeasureWithoutFracture",
     plus("measure:\n  tips:\n    - {name: a, at: [0.5, 0.5], direction: [1, 0]}"),
     "bad.yaml:8: measure: measure follows cracks through the damage field, which needs "
     "effects.fracture: true (allowed: effects: {fracture: true})"},
    {"MeasurePublishedWord", plus(measured() + "  published: {a: {angle_deg: steep}}"),
     "bad.yaml:12: measure.published.a.angle_deg: expected a number, got 'steep'"},
    {"MeasurePublishedListOfLists", plus(measured() + "  published: {a: [[1, 2]]}"),
     "bad.yaml:12: measure.published.a.0: expected a number, got a list"},
    {"MeasurePublishedNotAMap", plus(measured() + "  published: 5"),
     "bad.yaml:12: measure.published: expected a map of names to published values, got '5'"},
    {"MeasureSetThreshold",
     plus(measured()),
     "--set measure.damage_threshold: damage_threshold must lie in (0, 1), got 0",
     {{"measure.damage_threshold", "0"}}},
    {"NameWithSlash", replace_line(1, "name: a/b"),
     "bad.yaml:1: name: name 'a/b' cannot be used in output file names"},
    {"SyntaxError", replace_line(6, "  - {shape: box, min: [0, 0, max: [1, 1]}"),
     "bad.yaml:6: YAML syntax error"},
    {"EmptyFile", "# nothing here\n", "bad.yaml: the scene is empty"},
    {"TopLevelList", "- name: t\n", "bad.yaml:1: the top level of a scene must be a map"},
    {"SetIntoScalar", kMinimal, "--set name.x: cannot set 'x' inside 'name'", {{"name.x", "1"}}},
    {"SetNotAnIndex",
     kMinimal,
     "--set body.first.spacing: 'body' is a list: use an item number",
     {{"body.first.spacing", "1"}}},
    {"SetIndexOutOfRange",
     kMinimal,
     "--set body.3.spacing: item 3 is out of range: 'body' has 1 item (allowed: 0 to 0)",
     {{"body.3.spacing", "0.1"}}},
    {"SetUnknownKey",
     kMinimal,
     "--set tiem: unknown key 'tiem', did you mean 'time'?",
     {{"tiem.end", "1"}}},
    {"SetNegativeSpacing",
     kMinimal,
     "--set body.0.spacing: spacing must be > 0, got -1 (allowed: > 0)",
     {{"body.0.spacing", "-1"}}},
    {"SetWrongType",
     kMinimal,
     "--set time.end: expected a number, got a list",
     {{"time.end", "[1, 2]"}}},
    {"SetUnreadableValue",
     kMinimal,
     "--set time.end: cannot read the value '[1' as YAML",
     {{"time.end", "[1"}}},
    // Hostile trees (found by fuzzing, tests/fuzz): without the check the reader recursed
    // forever on a cycle and expanded alias ladders without bound.
    {"AliasInsideItsOwnValue",
     replace_line(6, "  - &part {shape: union, of: [*part], spacing: 0.1, material: glass}"),
     "bad.yaml:6: body.0.of.0: an alias stands for a value that contains this alias"},
    {"AliasCycleThroughAMap", plus("no_fail: &list\n  - {shape: union, of: *list}"),
     "bad.yaml:8: no_fail.0.of: an alias stands for a value that contains this alias"},
    {"AliasLadder", alias_ladder(14), "aliases expand to more than 10000 repeated values"},
    {"NestedTooDeep", nested_lists(64),
     // the value with 64 containers above it: the root map, the time map and 62 lists
     "bad.yaml:7: time.end" + repeated(".0", 62) + ": values are nested more than 64 levels deep"},
    {"SetAliasCycle",
     kMinimal,
     "--set no_fail: cannot use the value '&x [{shape: union, of: *x}]': 0.of: an alias stands for "
     "a value that contains this alias",
     {{"no_fail", "&x [{shape: union, of: *x}]"}}},
    {"SetInsideNewMap",
     kMinimal,
     "--set effects.fracture: expected true or false, got 'maybe'",
     {{"effects", "{fracture: maybe}"}}},
};

class BadSceneTest : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadSceneTest, IsRefusedWithLocation) {
  const BadScene& c = GetParam();
  try {
    parse_scene(c.yaml, "bad.yaml", c.overrides);
    FAIL() << "accepted:\n" << c.yaml;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos)
        << "message:  " << e.what() << "\nexpected: " << c.expected;
  }
}

INSTANTIATE_TEST_SUITE_P(Table, BadSceneTest, ::testing::ValuesIn(kBadScenes),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace dhpd::scene
