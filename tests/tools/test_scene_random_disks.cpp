// The random-disks shape in a scene (CMAME 2017 §5.2 inclusion layouts): the region is the union
// of the generated disks, the resolved scene records them, and the reader refuses bad values with
// file, line and key.
#include <gtest/gtest.h>

#include <cstdint>
#include <ostream>
#include <string>

#include "engine/base/errors.hpp"
#include "geometry/random_disks.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

geometry::RandomDisksSpec plate_spec(std::uint64_t seed) {
  geometry::RandomDisksSpec spec;
  spec.box.max = {3.0, 3.0, 0.0};
  spec.count = 25;
  spec.radius_min = 0.1;
  spec.radius_max = 0.25;
  spec.gap = 0.03;
  spec.seed = seed;
  return spec;
}

// The scene: a random-disks region, its errors (file:line: key: message (allowed: ...)).
constexpr const char* kScene = R"(name: t
dimension: 2
materials:
  matrix: {E: 1.0e9, rho: 1000, G0: 1.0}
  stiff: {E: 2.0e9, rho: 1000, G0: 2.0}
body:
  - {shape: box, min: [0, 0], max: [3, 3], spacing: 0.05, material: matrix}
time: {end: 1.0}
material_regions:
  - material: stiff
    region:
      shape: random-disks
      min: [0, 0]
      max: [3, 3]
      count: 25
      radius: [0.1, 0.25]
      gap: 0.03
      seed: 7
)";

scene::Scene scene_with(const std::string& extra) {
  return scene::parse_scene(std::string(kScene) + extra, "inc.yaml", {});
}

TEST(RandomDisksScene, IsTheUnionOfTheGeneratedDisks) {
  const auto s = scene_with("");
  ASSERT_EQ(s.material_regions.size(), 1u);
  const auto expected = geometry::place_random_disks(plate_spec(7)).shape();
  EXPECT_EQ(s.material_regions[0].region, expected);
}

TEST(RandomDisksScene, ResolvedSceneRecordsTheDisksAndReadsBackTheSame) {
  const auto first = scene_with("      cover: [[1.0, 1.5]]\n");
  const std::string text = scene::resolved_yaml(first);
  EXPECT_EQ(text.find("random-disks"), std::string::npos) << text;  // written out as disks
  const auto second = scene::parse_scene(text, "resolved.yaml", {});
  EXPECT_EQ(second.material_regions.at(0).region, first.material_regions.at(0).region);
  EXPECT_EQ(scene::resolved_yaml(second), text);
}

struct Refused {
  std::string name, override_value, path, expected;
};

std::ostream& operator<<(std::ostream& os, const Refused& r) {
  return os << r.name;
}

const std::vector<Refused> kRefused = {
    {"CountZero", "0", "count",
     "inc.yaml:15: material_regions.0.region.count: count must be an "
     "integer > 0, got 0 (allowed: integers >= 1)"},
    {"CountTooLarge", "1001", "count",
     "inc.yaml:15: material_regions.0.region.count: count must be at most 1000, got 1001 "
     "(allowed: 1 to 1000)"},
    {"TooMany", "200", "count", "inc.yaml:15: material_regions.0.region.count: could place only "},
    {"RadiiReversed", "[0.25, 0.1]", "radius",
     "inc.yaml:16: material_regions.0.region.radius: the smallest radius 0.25 is larger than the "
     "largest 0.1 (allowed: [smallest, largest] with smallest <= largest)"},
    {"RadiusTooLarge", "[0.1, 1.6]", "radius",
     "inc.yaml:16: material_regions.0.region.radius: a disk of radius 1.6 does not fit in the "
     "box, whose x extent is 3 (allowed: largest radius <= 1.5)"},
    {"RadiusNegative", "[-0.1, 0.2]", "radius",
     "inc.yaml:16: material_regions.0.region.radius.0: the smallest radius must be > 0, got -0.1 "
     "(allowed: > 0)"},
    {"RadiusOneNumber", "0.1", "radius", "inc.yaml:16: material_regions.0.region.radius: "},
    {"GapNegative", "-0.01", "gap",
     "inc.yaml:17: material_regions.0.region.gap: gap must be >= 0, got -0.01 (allowed: >= 0)"},
    {"SeedNegative", "-3", "seed",
     "inc.yaml:18: material_regions.0.region.seed: seed must be an integer >= 0, got -3 "
     "(allowed: >= 0)"},
    {"SeedNotWhole", "1.5", "seed",
     "inc.yaml:18: material_regions.0.region.seed: expected an integer, got '1.5'"},
};

class RandomDisksRefused : public ::testing::TestWithParam<Refused> {};

TEST_P(RandomDisksRefused, NamesFileLineKeyAndAllowed) {
  const Refused& r = GetParam();
  std::string text = kScene;
  const std::string key = "      " + r.path + ": ";
  const auto at = text.find(key);
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find('\n', at);
  text.replace(at, end - at, key + r.override_value);
  try {
    scene::parse_scene(text, "inc.yaml", {});
    FAIL() << "accepted:\n" << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(r.expected), std::string::npos)
        << "message:  " << e.what() << "\nexpected: " << r.expected;
  }
}

INSTANTIATE_TEST_SUITE_P(Table, RandomDisksRefused, ::testing::ValuesIn(kRefused),
                         [](const auto& info) { return info.param.name; });

void expect_refused(const std::string& extra, const std::string& expected) {
  try {
    scene_with(extra);
    FAIL() << "accepted:\n" << extra;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
        << "message:  " << e.what() << "\nexpected: " << expected;
  }
}

TEST(RandomDisksScene, RefusesCoverAndClearThatCannotHold) {
  // A cover point at the clear point: no disk can hold it and keep the gap.
  expect_refused("      cover: [[1.0, 1.0]]\n      clear: [[1.0, 1.0]]\n",
                 "inc.yaml:19: material_regions.0.region.cover.0: no disk covering this point "
                 "fits in 1000 draws (disk 1 of 25)");
  expect_refused("      clear: [[1, 1, 1]]\n",
                 "inc.yaml:19: material_regions.0.region.clear.0: expected a list of 2 numbers");
  expect_refused("      seeds: 3\n",
                 "inc.yaml:19: material_regions.0.region.seeds: unknown key 'seeds', did you mean "
                 "'seed'?");
}

TEST(RandomDisksScene, RefusesMoreCoverPointsThanDisks) {
  std::string text = kScene;
  text.replace(text.find("count: 25"), 9, "count: 1");
  try {
    scene::parse_scene(text + "      cover: [[1, 1], [2, 1]]\n", "inc.yaml", {});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inc.yaml:19: material_regions.0.region.cover: 2 points "
                                         "to cover but only 1 disks (allowed: at most count = 1 "
                                         "points)"),
              std::string::npos)
        << e.what();
  }
}

TEST(RandomDisksScene, ExistsOnlyIn2d) {
  const std::string text =
      "name: t\ndimension: 3\nmaterials:\n  g: {E: 1.0e9, rho: 1000}\nbody:\n"
      "  - {shape: box, min: [0, 0, 0], max: [1, 1, 1], spacing: 0.1, material: g}\n"
      "time: {end: 1.0}\nno_fail:\n  - {shape: random-disks, min: [0, 0, 0], max: [1, 1, 1]}\n";
  try {
    scene::parse_scene(text, "inc.yaml", {});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("inc.yaml:9: no_fail.0.shape: shape 'random-disks' exists "
                                         "only in 2D scenes"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace dhpd
