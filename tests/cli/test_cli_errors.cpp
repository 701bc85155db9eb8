// End-to-end: refused scenes and command lines exit 2 with a located message and write nothing.
#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

struct BadScene {
  std::string name;
  std::string yaml;               ///< written to bad.yaml
  std::vector<std::string> sets;  ///< --set arguments
  std::string expected;           ///< start of the message: "bad.yaml:LINE: key.path: ..."
};

void PrintTo(const BadScene& bad, std::ostream* os) {
  *os << bad.name;
}

/// kPlate with line `line` replaced by `text`.
BadScene edit(std::string name, int line, const std::string& text, std::string expected) {
  return {std::move(name), with_line(kPlate, line, text), {}, std::move(expected)};
}
/// The plate with a patch of half spacing in it (two time levels).
constexpr const char* kPatchBody =
    "body=[{shape: box, min: [0, 0], max: [0.01, 0.005], spacing: 0.0005, material: glass}, "
    "{shape: box, min: [0.004, 0.001], max: [0.006, 0.004], spacing: 0.00025, material: glass}]";

/// kPlate with one `--set` override.
BadScene set(std::string name, std::string override_text, std::string expected) {
  return {std::move(name), kPlate, {std::move(override_text)}, std::move(expected)};
}

std::vector<BadScene> bad_scenes() {
  return {
      edit("UnknownKey", 16, "effects: {fractur: true}",
           "bad.yaml:16: effects.fractur: unknown key 'fractur', did you mean 'fracture'?"),
      edit("UnknownNestedKey", 13, "    fixd: true",
           "bad.yaml:13: boundary_conditions.0.fixd: unknown key 'fixd', did you mean 'fixed'?"),
      edit("DuplicateKey", 6, "  glass:\n    E: 72.0e9\n    rho: 2440\n    G0: 3.8\n    rho: 1000",
           "bad.yaml:10: materials.glass.rho: duplicate key 'rho' (first given on line 8)"),
      edit("YoungModulusZero", 6, "  glass: {E: 0, rho: 2440, G0: 3.8}",
           "bad.yaml:6: materials.glass.E: E must be > 0, got 0 (allowed: > 0)"),
      edit("MissingModulus", 6, "  glass: {rho: 2440, G0: 3.8}",
           "bad.yaml:6: materials.glass: missing required key 'E'"),
      edit("MissingDimension", 2, "# no dimension", "bad.yaml:1: missing required key 'dimension'"),
      edit("RegionOutsideBody", 14,
           "  - region: {shape: box, min: [0.02, 0.02], max: [0.03, 0.03]}",
           "bad.yaml:14: boundary_conditions.1.region: selects no particle"),
      edit("FixedStepTooLarge", 17, "time: {steps: 60, dt: 1.0}",
           "bad.yaml:17: time.dt: 1 s is above the stable time step"),
      edit("CrackWithThreePoints", 10, "  - [[0.0, 0.0025], [0.002, 0.0025], [0.004, 0.0025]]",
           "bad.yaml:10: cracks.0: expected a list of 2 end points"),
      edit("YamlSyntaxError", 6, "  glass: {E: 72.0e9, rho: 2440, G0: 3.8}}",
           "bad.yaml:6: YAML syntax error: illegal flow end"),
      edit("PoissonRatioMismatch", 6, "  glass: {E: 72.0e9, rho: 2440, G0: 3.8, nu: 0.25}",
           "bad.yaml:6: materials.glass.nu: bond-based peridynamics fixes nu = 0.333333"),
      edit("UnknownField", 18, "output: {every: 20, fields: [strain_energy]}",
           "bad.yaml:18: output.fields.0: unknown field 'strain_energy'"),
      edit("SafetyAboveOne", 17, "time: {steps: 60, safety: 1.5}",
           "bad.yaml:17: time.safety: safety must lie in (0, 1], got 1.5"),
      edit("EndAndSteps", 17, "time: {steps: 60, end: 1.0e-6}",
           "bad.yaml:17: time: give either end or steps, not both"),
      edit("MeasureWithoutFracture", 16,
           "effects: {fracture: false}\nmeasure: {tips: [{name: a, at: [0.004, 0.0025], "
           "direction: [1, 0]}]}",
           "bad.yaml:17: measure: measure follows cracks through the damage field, which needs "
           "effects.fracture: true"),
      set("SetMeasureTipOutsideBody",
          "measure={tips: [{name: a, at: [0.02, 0.0025], direction: [1, 0]}]}",
          "--set measure.tips.0.at: the notch tip [0.02, 0.0025] lies outside the body's "
          "bounding box (allowed: [0, 0] to [0.01, 0.005])"),
      set("SetProbeOutsideBody", "output.probes=[{name: P, at: [0.02, 0.0025]}]",
          "--set output.probes.0.at: the probe [0.02, 0.0025] lies outside the body's "
          "bounding box (allowed: [0, 0] to [0.01, 0.005])"),
      set("SetSpacingTooLarge", "body.0.spacing=0.05",
          "--set body.0.spacing: spacing 0.05 is larger than the part's smallest extent 0.005"),
      set("SetPathOutOfRange", "body.3.spacing=1e-3",
          "--set body.3.spacing: item 3 is out of range: 'body' has 1 item"),
      set("SetThroughPlainValue", "name.x=1", "--set name.x: cannot set 'x' inside 'name'"),
      set("SetBadValue", "time.steps=-1", "--set time.steps: steps must be an integer > 0"),
      set("SetWithoutValue", "time.steps", "--set time.steps: expected key.path=value"),
      set("SetInitialVelocityOutsideBody",
          "initial_conditions=[{region: {shape: box, min: [0.02, 0.02], max: [0.03, 0.03]}, "
          "velocity: [22.0, 0.0]}]",
          "--set initial_conditions.0.region: selects no particle"),
      {"MultirateFixedStepAboveTheCoarseOne",
       kPlate,
       {kPatchBody, "time.multirate=true", "time.dt=1e-6"},
       "bad.yaml:17: time.dt: 1e-06 s is above the stable step of the coarsest particles "
       "(time.multirate) 1.50025e-07 s"},
      {"MultirateNeedsMoreLevelsThanAllowed",
       kPlate,
       {kPatchBody, "time.multirate=true", "time.max_levels=1"},
       "bad.yaml:17: time.max_levels: the particles need 2 time levels"},
      set("MaxLevelsAboveTheLimit", "time.max_levels=20",
          "--set time.max_levels: 20 time levels: the finest step would be dt0 / 2^19 (allowed: 1 "
          "<= max_levels <= 16 (default 8))"),
      set("MultirateNotABoolean", "time.multirate=maybe",
          "--set time.multirate: expected true or false, got 'maybe'"),
      set("SetUnknownMapping", "effects.refinement={mapping: cubic}",
          "--set effects.refinement.mapping: unknown mapping 'cubic' (allowed: copy, linear, "
          "quadratic)"),
      set("SetStretchTriggerAboveOne", "effects.refinement={trigger: {stretch: 1.5}}",
          "--set effects.refinement.trigger.stretch: stretch (of s0) is a fraction, got 1.5"),
  };
}

class CliBadScene : public CliTest, public ::testing::WithParamInterface<BadScene> {};

TEST_P(CliBadScene, ExitsTwoWithLocatedMessageAndWritesNothing) {
  const auto& bad = GetParam();
  write("bad.yaml", bad.yaml);
  const auto r = dhpd({"run", "bad.yaml", "-o", "result", "-q"}, bad.sets);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("dhpd: error: " + bad.expected, 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(fs::exists(dir_ / "result"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));  // the scene's own output.directory

  const auto c = dhpd({"check", "bad.yaml"}, bad.sets);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_EQ(c.err, r.err);
  EXPECT_EQ(c.out, "");
}

INSTANTIATE_TEST_SUITE_P(Table, CliBadScene, ::testing::ValuesIn(bad_scenes()),
                         [](const auto& info) { return info.param.name; });

TEST_F(CliTest, BadCommandLinesExitTwo) {
  const auto missing = dhpd({"run", "missing-scene.yaml", "-o", "result", "-q"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("missing-scene.yaml"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("cannot open"), std::string::npos) << missing.err;
  EXPECT_EQ(dhpd({"check", "missing-scene.yaml"}).code, 2);

  const auto unknown = dhpd({"run", "plate.yaml", "-o", "result", "--bogus-option"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("--bogus-option"), std::string::npos) << unknown.err;
  EXPECT_EQ(dhpd({}).code, 2);  // no subcommand
  EXPECT_EQ(dhpd({"run", "plate.yaml", "-o", "result", "-t", "0"}).code, 2);
  EXPECT_EQ(dhpd({"frobnicate", "plate.yaml"}).code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "result"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// ---- A good run writes every output ----

}  // namespace
