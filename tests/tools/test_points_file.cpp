// Particles from a text file (`x y [z] volume [material]`) and scenes with points-file and meshed
// parts, built and run through the same builder the command line uses.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "engine/base/errors.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/points_file.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;
using scene::PointsFileOptions;

PointsFileOptions options_2d() {
  PointsFileOptions o;
  o.dim = 2;
  o.section = 2e-3;  // thickness: the file's volumes are divided by it
  o.materials = {"glass", "steel"};
  return o;
}

geometry::PointSet parse(const std::string& text, const PointsFileOptions& o) {
  std::istringstream in(text);
  return scene::parse_points(in, "pts.txt", o);
}

/// The InputError message of parsing `text`, or "" when it parses.
std::string error_of(const std::string& text, const PointsFileOptions& o) {
  try {
    parse(text, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PointsFile, ReadsCoordinatesVolumesAndMaterials) {
  const std::string text =
      "# x y volume material\n"
      "\n"
      "0.0 0.0 2e-9 glass   # by name\n"
      "  1e-3\t0 8e-9 1\n"
      "2e-3 +1e-3 2e-9\n";
  auto o = options_2d();
  o.default_material = 1;
  o.part = 4;
  const auto pts = parse(text, o);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts.position[1][0], 1e-3);
  EXPECT_EQ(pts.position[2][1], 1e-3);
  EXPECT_DOUBLE_EQ(pts.cell_measure[0], 1e-6);  // 2e-9 m³ / 2e-3 m
  // Δx is the equivalent diameter (CMAME 2017 §6): the disk of area 1e-6 m² has diameter
  // 2·sqrt(1e-6/π) = 1.128e-3 m; cell-side gives the lattice spacing sqrt(area) back.
  EXPECT_DOUBLE_EQ(pts.spacing[0], 2.0 * std::sqrt(1e-6 / std::numbers::pi));
  EXPECT_DOUBLE_EQ(pts.spacing[1], 2.0 * std::sqrt(4e-6 / std::numbers::pi));
  o.size_rule = geometry::PointSize::CellSide;
  const auto cells = parse(text, o);
  EXPECT_DOUBLE_EQ(cells.spacing[0], 1e-3);
  EXPECT_DOUBLE_EQ(cells.spacing[1], 2e-3);
  EXPECT_EQ(pts.material, (std::vector<int>{0, 1, 1}));
  EXPECT_EQ(pts.part, (std::vector<int>{4, 4, 4}));
}

TEST(PointsFile, DimensionDecidesTheColumns) {
  PointsFileOptions o;
  o.dim = 3;
  o.materials = {"m"};
  const auto pts = parse("1 2 3 8 m\n", o);
  EXPECT_EQ(pts.position[0][2], 3.0);
  EXPECT_DOUBLE_EQ(pts.spacing[0], std::cbrt(6.0 * 8.0 / std::numbers::pi));  // ball of 8 m³
  o.dim = 1;
  o.section = 0.5;  // cross-section area
  const auto bar = parse("0.25 1.5 0\n", o);
  EXPECT_DOUBLE_EQ(bar.cell_measure[0], 3.0);
  EXPECT_DOUBLE_EQ(bar.spacing[0], 3.0);  // in 1D the equivalent diameter is the cell length
  o.dim = 3;
  o.section = 1.0;
  o.size_rule = geometry::PointSize::CellSide;
  EXPECT_DOUBLE_EQ(parse("1 2 3 8 m\n", o).spacing[0], 2.0);  // cbrt(8)
}

// Found by fuzzing (tests/fuzz): a volume far from the section's scale gave particles a cell
// measure of infinity or 0 (and so a zero spacing and horizon) without a word.
TEST(PointsFile, VolumeThatOverflowsOrUnderflowsTheCellMeasureIsRefused) {
  auto o = options_2d();
  o.section = 1e-300;  // a (silly but valid) thickness
  EXPECT_EQ(error_of("0 0 1e-9 glass\n0 0 1e308 glass\n", o),
            "pts.txt:2: volume 1e308 divided by the section 1e-300 (the thickness in 2D, the area "
            "in 1D) gives a cell measure of inf, which is not a finite number > 0");
  o.section = 1e300;
  EXPECT_EQ(error_of("0 0 1e-30 glass\n", o),
            "pts.txt:1: volume 1e-30 divided by the section 1e+300 (the thickness in 2D, the area "
            "in 1D) gives a cell measure of 0, which is not a finite number > 0");
  o.section = 1.0;
  EXPECT_EQ(parse("0 0 1e-310 glass\n", o).cell_measure[0], 1e-310);  // tiny but > 0 is kept
  // The equivalent diameter of the largest volumes stays finite (cbrt(6V/π) computed as
  // cbrt(6/π)·cbrt(V): 6V alone overflows).
  o.dim = 3;
  const auto huge = parse("0 0 0 1.7e308 glass\n", o);
  EXPECT_TRUE(std::isfinite(huge.spacing[0]));
  EXPECT_NEAR(huge.spacing[0] / std::cbrt(1.7e308), std::cbrt(6.0 / std::numbers::pi), 1e-12);
}

TEST(PointsFile, EachErrorNamesFileLineAndProblem) {
  const auto o = options_2d();
  const std::string good = "0 0 1e-9 glass\n";
  EXPECT_EQ(error_of(good + "0 x 1e-9 glass\n", o),
            "pts.txt:2: column 2 (y): 'x' is not a finite number");
  EXPECT_EQ(error_of(good + "0 0 nan glass\n", o),
            "pts.txt:2: column 3 (volume): 'nan' is not a finite number");
  EXPECT_EQ(error_of("\n# c\n0 0\n", o),
            "pts.txt:3: expected 3 or 4 columns (x y volume [material]), got 2");
  EXPECT_EQ(error_of(good + "0 0 1e-9 glass 7\n", o),
            "pts.txt:2: expected 3 or 4 columns (x y volume [material]), got 5");
  EXPECT_EQ(error_of(good + "0 0 0 glass\n", o), "pts.txt:2: volume must be > 0, got 0");
  EXPECT_EQ(error_of(good + "0 0 -1e-9 glass\n", o), "pts.txt:2: volume must be > 0, got -1e-9");
  EXPECT_EQ(error_of(good + "0 0 1e-9 2\n", o),
            "pts.txt:2: unknown material index '2' (allowed: glass (0), steel (1))");
  EXPECT_EQ(error_of(good + "0 0 1e-9 -1\n", o),
            "pts.txt:2: unknown material index '-1' (allowed: glass (0), steel (1))");
  EXPECT_EQ(error_of(good + "0 0 1e-9 glas\n", o),
            "pts.txt:2: unknown material name 'glas' (allowed: glass (0), steel (1))");
  EXPECT_EQ(error_of(good + "0 0 1e-9\n", o),
            "pts.txt:2: no material column and no default material: add the material as the "
            "last column");
  EXPECT_EQ(error_of("# only a comment\n\n", o),
            "pts.txt: the points file holds no point (expected lines of 'x y volume [material]')");
  EXPECT_THROW(scene::read_points_file("/nonexistent/dhpd/pts.txt", o), InputError);
}

/// A fresh directory for scene and points files, removed at the end of the test.
class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device random;
    dir_ = fs::temp_directory_path() / ("dhpd_irregular_" + std::string(info->name()) + "_" +
                                        std::to_string(getpid()) + "_" + std::to_string(random()));
    fs::create_directories(dir_ / "data");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

constexpr const char* kHeader = R"(name: irregular
dimension: 2
thickness: 0.002
materials:
  glass: {E: 72.0e9, rho: 2440}
  steel: {E: 2.0e11, rho: 7850}
)";

constexpr const char* kTail = R"(boundary_conditions:
  - region: {shape: box, min: [0, 0], max: [0.004, 0.02]}
    fixed: true
initial_conditions:
  - region: {shape: box, min: [0, 0], max: [0.04, 0.02]}
    strain: [1.0e-4, 0]
    origin: [0, 0]
time: {steps: 20}
)";

TEST_F(SceneFiles, MeshedPartRunsThroughTheBuilder) {
  const std::string body =
      "body:\n"
      "  - {shape: box, min: [0, 0], max: [0.04, 0.02], material: glass,\n"
      "     mesh: {size: 0.001, grading: {from: [0.04, 0.01], rate: 0.1}}}\n";
  const auto file = write("mesh.yaml", std::string(kHeader) + body + kTail);
  const auto scene = scene::load_scene(file.string());
  ASSERT_EQ(scene.body[0].kind, scene::PartKind::Mesh);
  const std::string resolved = scene::resolved_yaml(scene);
  EXPECT_NE(resolved.find("mesh: {size: 0.001, grading: {from: [0.04, 0.01], rate: 0.1}}"),
            std::string::npos)
      << resolved;
  EXPECT_EQ(scene::resolved_yaml(scene::parse_scene(resolved, "again.yaml")), resolved);
  auto sim = scene::build_simulation(scene);
  const auto& p = sim->particles();
  double volume = 0;
  for (std::size_t i = 0; i < p.size(); ++i) volume += p.volume[i];
  EXPECT_NEAR(volume / (0.04 * 0.02 * 0.002), 1.0, 1e-10);
  // Every node has its own spacing: the derived table shows only the smallest and largest.
  const std::string derived = scene::derived_yaml(scene, *sim);
  std::size_t rows = 0;
  for (auto at = derived.find("- material:"); at != std::string::npos;
       at = derived.find("- material:", at + 1))
    ++rows;
  EXPECT_EQ(rows, 2u) << derived;
  sim->run_steps(20);
  const auto e = sim->energies();
  EXPECT_GT(e.strain + e.kinetic, 0.0);
  EXPECT_NO_THROW(sim->check_stable(e));
  std::printf("meshed scene: %zu particles, %zu bonds, dt %.3g s\n", p.size(),
              sim->bonds().bond_count(), sim->dt());
}

TEST(MeshScene, TetrahedralPartBesideALatticePartRuns) {
  const std::string text = R"(name: brick
dimension: 3
materials:
  steel: {E: 2.0e11, rho: 7850}
body:
  - {shape: box, min: [0.02, 0, 0], max: [0.03, 0.01, 0.01], spacing: 0.001, material: steel}
  - {shape: box, min: [0, 0, 0], max: [0.02, 0.01, 0.01], mesh: {size: 0.002}, material: steel}
initial_conditions:
  - region: {shape: box, min: [0, 0, 0], max: [0.03, 0.01, 0.01]}
    velocity: [0, 0, 1.0]
    gaussian: {center: [0.015, 0.005, 0.005], width: 0.005}
time: {steps: 10}
)";
  const auto scene = scene::parse_scene(text, "brick.yaml");
  auto sim = scene::build_simulation(scene);
  const auto& p = sim->particles();
  double volume = 0;
  for (std::size_t i = 0; i < p.size(); ++i) volume += p.volume[i];
  // The lattice points lie at cell centres, none on the shared face x = 0.02, so the later
  // meshed part keeps all its nodes and the volumes add up to the body's.
  EXPECT_NEAR(volume / (0.03 * 0.01 * 0.01), 1.0, 1e-10);
  sim->run_steps(10);
  EXPECT_NO_THROW(sim->check_stable(sim->energies()));
  EXPECT_EQ(scene::resolved_yaml(scene::parse_scene(scene::resolved_yaml(scene), "r.yaml")),
            scene::resolved_yaml(scene));
  std::printf("3D meshed scene: %zu particles, %zu bonds\n", p.size(), sim->bonds().bond_count());
}

TEST_F(SceneFiles, PointsFilePartIsResolvedAgainstTheSceneFolder) {
  std::string points;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 40; ++i)
      points += std::to_string((i + 0.5) * 1e-3) + " " + std::to_string((j + 0.5) * 1e-3) +
                " 2e-9" + (i >= 30 ? " steel" : "") + "\n";
  write("data/plate.txt", "# a 40 x 20 lattice written out\n" + points);
  // A lattice written out keeps its lattice spacing with point_size: cell-side.
  const std::string body =
      "body:\n  - {points_file: data/plate.txt, point_size: cell-side, material: glass}\n";
  const auto file = write("file.yaml", std::string(kHeader) + body + kTail);
  const auto scene = scene::load_scene(file.string());
  EXPECT_EQ(scene.body[0].points_file, (dir_ / "data/plate.txt").lexically_normal().string());
  const std::string resolved = scene::resolved_yaml(scene);
  EXPECT_NE(resolved.find("point_size: cell-side"), std::string::npos) << resolved;
  EXPECT_EQ(scene::resolved_yaml(scene::parse_scene(resolved, "elsewhere/again.yaml")), resolved);
  auto sim = scene::build_simulation(scene);
  const auto& p = sim->particles();
  ASSERT_EQ(p.size(), 800u);
  int steel = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_DOUBLE_EQ(p.volume[i], 2e-9);
    EXPECT_DOUBLE_EQ(p.spacing[i], 1e-3);
    steel += p.material[i] == 1;
  }
  EXPECT_EQ(steel, 200);
  // By default the same file's points take the equivalent diameter (CMAME 2017 §6).
  const auto plain = write("plain.yaml", std::string(kHeader) +
                                             "body:\n  - {points_file: data/plate.txt, "
                                             "material: glass}\n" +
                                             kTail);
  const auto by_default = scene::load_scene(plain.string());
  EXPECT_NE(scene::resolved_yaml(by_default).find("point_size: equivalent-diameter"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(scene::build_simulation(by_default)->particles().spacing[0],
                   2.0 * std::sqrt(1e-6 / std::numbers::pi));
  sim->run_steps(20);
  EXPECT_NO_THROW(sim->check_stable(sim->energies()));
}

TEST_F(SceneFiles, BadPointsFileIsRefusedWithItsOwnLine) {
  write("bad.txt", "0 0 1e-9\n0 0 -1e-9\n");
  const std::string body = "body:\n  - {points_file: bad.txt, material: glass}\n";
  const auto file = write("bad.yaml", std::string(kHeader) + body + kTail);
  try {
    scene::build_simulation(scene::load_scene(file.string()));
    FAIL() << "a negative volume was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir_ / "bad.txt").string() + ":2: volume must be > 0, got -1e-9");
  }
}

}  // namespace
}  // namespace dhpd
