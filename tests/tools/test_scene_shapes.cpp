// Shapes in a scene: a plate with inclusions (CMAME 2017 §5.2) whose bonds use their owner's
// material, and parts or regions that hold no particle are refused.
#include <gtest/gtest.h>

#include <string>

#include "engine/base/errors.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::scene {
namespace {

// Two steel disks in a glass plate pulled apart at both ends (CMAME 2017 §5.2 style).
const char* kInclusions = R"(name: inclusions
dimension: 2
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
  steel: {E: 2.0e11, rho: 7850, G0: 1.0e4}
body:
  - {shape: box, min: [0, 0], max: [0.05, 0.02], spacing: 0.0005, material: glass}
material_regions:
  - region: {shape: disk, center: [0.015, 0.01], radius: 0.003}
    material: steel
  - region: {shape: disk, center: [0.035, 0.01], radius: 0.003}
    material: steel
boundary_conditions:
  - region: {shape: box, min: [0, 0], max: [0.0015, 0.02]}
    velocity: {x: -2}
  - region: {shape: box, min: [0.0485, 0], max: [0.05, 0.02]}
    velocity: {x: 2}
effects: {fracture: true}
time: {steps: 300}
)";

TEST(Inclusions, BondsOwnedByInclusionParticlesUseTheInclusionMaterial) {
  const Scene s = parse_scene(kInclusions, "inclusions.yaml");
  auto sim = build_simulation(s);
  const auto& p = sim->particles();
  const auto& b = sim->bonds();
  const auto rule = sim->setup().partial_volume;
  std::size_t steel = 0, steel_owned = 0, mixed = 0, expected = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const geometry::Vec3 x{p.reference_position[0][i], p.reference_position[1][i], 0};
    const bool inside =
        s.material_regions[0].region.contains(x, 2) || s.material_regions[1].region.contains(x, 2);
    expected += inside;
    steel += p.material[i] == 1;
    EXPECT_EQ(p.material[i], inside ? 1 : 0);
    const auto& own = sim->setup().materials[static_cast<std::size_t>(p.material[i])];
    const double C = micromodulus(own, sim->setup().section, p.horizon[i]);
    EXPECT_DOUBLE_EQ(sim->micromodulus()[i], C);
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      const auto j = static_cast<std::size_t>(b.other[k]);
      const auto in_j = b.find(j, static_cast<std::int32_t>(i));
      ASSERT_GE(in_j, 0);
      // The entry of j in row i sums this bond (i's material) and the reverse one (j's), and row
      // j's entry holds the same stiffness bits (single precision, docs/theory.md §18).
      ASSERT_TRUE(b.has_own(k) && b.has_dual(k));
      const auto& theirs = sim->setup().materials[static_cast<std::size_t>(p.material[j])];
      const double C_j = micromodulus(theirs, sim->setup().section, p.horizon[j]);
      const double L = b.length(k);
      const double both = C * bond_weight(p, rule, i, j, L) + C_j * bond_weight(p, rule, j, i, L);
      EXPECT_NEAR(static_cast<double>(b.stiffness[k]) * b.stiffness_scale, both, 6e-8 * both);
      EXPECT_EQ(b.stiffness[k], b.stiffness[in_j]);
      steel_owned += p.material[i] == 1;
      mixed += p.material[i] != p.material[j];
    }
  }
  EXPECT_EQ(steel, expected);
  EXPECT_EQ(steel, 224u);
  EXPECT_GT(steel, 2u * 100u);  // π (3 mm)² / (0.5 mm)² ≈ 113 per disk
  EXPECT_GT(steel_owned, 0u);
  EXPECT_GT(mixed, 0u);
  sim->run_steps(*s.time.steps);
  EXPECT_NO_THROW(sim->check_stable(sim->energies()));
  EXPECT_EQ(sim->steps_done(), 300);
}

std::string build_error(const std::string& yaml) {
  try {
    build_setup(parse_scene(yaml, "bad.yaml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ShapeScenes, PartOrRegionWithoutParticlesIsRefused) {
  const std::string head = "name: t\ndimension: 2\nmaterials:\n  glass: {E: 1.0e9, rho: 1000}\n";
  const std::string empty_part =
      "body:\n  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, material: glass}\n"
      "  - shape: difference\n    of: [{shape: box, min: [0, 0], max: [1, 1]}, {shape: disk, "
      "center: [0.5, 0.5], radius: 2}]\n    spacing: 0.1\n    material: glass\n";
  EXPECT_NE(build_error(head + empty_part + "time: {end: 1.0}\n")
                .find("bad.yaml:7: body.1: this part's shape holds no lattice point"),
            std::string::npos);
  const std::string plate =
      "body:\n  - {shape: box, min: [0, 0], max: [1, 1], spacing: 0.1, material: glass}\n";
  EXPECT_NE(build_error(head + plate +
                        "material_regions: [{region: {shape: disk, center: [3, 3], radius: 1}, "
                        "material: glass}]\ntime: {end: 1.0}\n")
                .find("bad.yaml:7: material_regions.0.region: selects no particle"),
            std::string::npos);
  const std::string disk_part =
      "body:\n  - {shape: disk, center: [0.5, 0.5], radius: 0.5, spacing: 0.1, material: glass}\n";
  EXPECT_EQ(build_error(head + disk_part + "time: {end: 1.0}\n"), "accepted");
}

}  // namespace
}  // namespace dhpd::scene
