// Crack measurements (IJNME 2016 eq. 59; docs/theory.md §15) on damage fields painted by hand: a
// straight crack at 30° growing at known rates, a Y-shaped fork, a damaged blob away from the
// notch, a store that is refined between measurements; and the `measure` block of a scene.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "engine/base/errors.hpp"
#include "tests/support/engine.hpp"
#include "tests/support/scene_samples.hpp"
#include "tools/measure/crack_measure.hpp"
#include "tools/scene/build.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::measure {
namespace {

constexpr double kDx = 1e-3;         // lattice spacing (m)
constexpr double kFactor = 3.015;    // horizon / spacing
constexpr double kInterval = 1e-5;   // time between measurements (s)
const Vec3 kNotch{0.005, 0.005, 0};  // notch tip, on a lattice corner

Section plane_stress() {
  Section s;
  s.dim = 2;
  s.thickness = 1e-3;
  return s;
}

/// An undamaged lattice plate [0, width] x [0, height] of spacing dx.
ParticleStore plate(double width, double height, double dx) {
  geometry::Box box;
  box.max = {width, height, 0};
  const auto pts = geometry::fill_lattice({{box, dx, 0}}, 2);
  return test::store_from_points(pts, 2, kFactor, plane_stress());
}

/// φ = 1 on every particle within `half_width` of the segment a–b.
void paint_segment(ParticleStore& p, const Vec3& a, const Vec3& b, double half_width) {
  const Vec3 ab = b - a;
  const double length2 = geometry::dot(ab, ab);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 x{p.reference_position[0][i], p.reference_position[1][i], 0};
    const double t = length2 > 0 ? std::clamp(geometry::dot(x - a, ab) / length2, 0.0, 1.0) : 0;
    if (geometry::norm(x - (a + t * ab)) <= half_width) p.damage[i] = 1.0;
  }
}

Vec3 unit(double degrees) {
  const double r = degrees * std::numbers::pi / 180.0;
  return {std::cos(r), std::sin(r), 0};
}

Settings one_tip(std::int64_t smoothing) {
  Settings s;
  s.smoothing = smoothing;
  s.tips = {{"notch", kNotch, {2, 0, 0}, std::nullopt, std::nullopt}};  // direction: not unit
  return s;
}

/// Crack lengths (in spacings) at measurements 0, 1, ...: nothing, 1.5 Δx (within one horizon of
/// the notch), then 10 Δx per interval (1000 m/s) for six intervals, then 20 Δx (2000 m/s).
const std::vector<double> kLengths{0, 1.5, 12, 22, 32, 42, 52, 62, 82, 102, 122, 142};

/// Grows a 1.5 Δx wide crack at 30° from the notch through kLengths, measuring after each.
std::vector<TipRow> grow_straight_crack(CrackTracker& tracker) {
  ParticleStore p = plate(0.135, 0.085, kDx);
  std::vector<TipRow> rows;
  for (std::size_t l = 0; l < kLengths.size(); ++l) {
    if (kLengths[l] > 0)
      paint_segment(p, kNotch, kNotch + kLengths[l] * kDx * unit(30), 0.75 * kDx);
    const auto r = tracker.measure(p, static_cast<std::int64_t>(10 * l), kInterval * l);
    EXPECT_EQ(r.size(), 1u);
    rows.push_back(r.at(0));
  }
  return rows;
}

TEST(CrackMeasure, StraightCrackAt30DegreesGivesAngleSpeedAndInitiation) {
  CrackTracker tracker(one_tip(1));
  const auto rows = grow_straight_crack(tracker);
  EXPECT_EQ(rows[0].branches, 0);  // nothing damaged: the tip is the notch tip
  EXPECT_EQ(rows[0].distance, 0.0);
  EXPECT_TRUE(std::isnan(rows[0].angle_deg));
  for (std::size_t l = 1; l < rows.size(); ++l) {
    EXPECT_NEAR(rows[l].distance, kLengths[l] * kDx, 1.0 * kDx) << l;
    EXPECT_GE(rows[l].path_length, rows[l].distance) << l;
    EXPECT_LE(rows[l].path_length, 1.1 * rows[l].distance + kDx) << l;
    EXPECT_EQ(rows[l].branches, 1) << l;  // a straight crack never branches
  }
  for (std::size_t l = 3; l <= 7; ++l) EXPECT_NEAR(rows[l].speed, 1000.0, 150.0) << l;
  for (std::size_t l = 8; l <= 11; ++l) EXPECT_NEAR(rows[l].speed, 2000.0, 150.0) << l;
  for (std::size_t l = 9; l <= 11; ++l) EXPECT_NEAR(rows[l].angle_deg, 30.0, 0.5) << l;
  const auto sum = tracker.summary();
  ASSERT_EQ(sum.size(), 1u);
  EXPECT_EQ(sum[0].name, "notch");
  ASSERT_TRUE(sum[0].initiation_time.has_value());
  // The crack meets the notch at the first damaged measurement (it runs once it is more than a
  // horizon out, from the second: 1.5 Δx is within one horizon).
  EXPECT_DOUBLE_EQ(*sum[0].initiation_time, 1 * kInterval);
  EXPECT_NEAR(*sum[0].angle_deg, 30.0, 0.5);
  EXPECT_NEAR(*sum[0].max_speed, 2000.0, 150.0);
  // Path advanced since the crack runs (130 Δx, lattice steps make it up to 8 % longer) over 9 Δt.
  EXPECT_GT(*sum[0].mean_speed, 130 * kDx / (9 * kInterval));
  EXPECT_LT(*sum[0].mean_speed, 1.1 * 130 * kDx / (9 * kInterval));
  EXPECT_TRUE(sum[0].branch_times.empty());
  EXPECT_TRUE(sum[0].branch_positions.empty());
  EXPECT_NEAR(geometry::norm(sum[0].tip - (kNotch + 142 * kDx * unit(30))), 0.0, 1.0 * kDx);
}

TEST(CrackMeasure, SmoothingAveragesTheSpeedOverIntervals) {
  CrackTracker tracker(one_tip(3));
  const auto rows = grow_straight_crack(tracker);
  // Fewer intervals at the start: measurement 1 uses one, measurement 2 two.
  EXPECT_NEAR(rows[1].speed, 1.5 * kDx / kInterval, 100.0);
  EXPECT_NEAR(rows[2].speed, 12 * kDx / (2 * kInterval), 100.0);
  for (std::size_t l = 5; l <= 7; ++l) EXPECT_NEAR(rows[l].speed, 1000.0, 100.0) << l;
  // Across the change of rate the three-interval speed lags: (82 − 42) / 3, (102 − 52) / 3.
  EXPECT_NEAR(rows[8].speed, 40.0 / 3 * kDx / kInterval, 100.0);
  EXPECT_NEAR(rows[9].speed, 50.0 / 3 * kDx / kInterval, 100.0);
  EXPECT_NEAR(rows[10].speed, 2000.0, 100.0);
  EXPECT_NEAR(*tracker.summary()[0].max_speed, 2000.0, 100.0);
}

TEST(CrackMeasure, ForkGivesOneBranchTimeAtTheFork) {
  ParticleStore p = plate(0.09, 0.06, kDx);
  const Vec3 notch{0.005, 0.03, 0}, fork = notch + Vec3{0.04, 0, 0};
  Settings s = one_tip(1);
  s.tips[0].at = notch;
  CrackTracker tracker(s);
  std::vector<int> branches;
  for (int l = 0; l <= 10; ++l) {
    const double stem = std::min(l, 4) * 10 * kDx, arm = std::max(l - 4, 0) * 5 * kDx;
    if (stem > 0) paint_segment(p, notch, notch + Vec3{stem, 0, 0}, 0.75 * kDx);
    if (arm > 0) {
      paint_segment(p, fork, fork + arm * unit(40), 0.75 * kDx);
      paint_segment(p, fork, fork + arm * unit(-40), 0.75 * kDx);
    }
    branches.push_back(tracker.measure(p, 10 * l, kInterval * l).at(0).branches);
  }
  EXPECT_EQ(branches[4], 1);   // the stem alone
  EXPECT_EQ(branches[10], 2);  // two arms 30 Δx long
  const auto sum = tracker.summary()[0];
  ASSERT_EQ(sum.branch_times.size(), 1u);
  // The arms are told apart once their centroids in one bin are > 2 horizons apart: a few Δx
  // past the fork, one or two measurements after the arms start (measurement 5).
  EXPECT_GE(sum.branch_times[0], 5 * kInterval);
  EXPECT_LE(sum.branch_times[0], 7 * kInterval);
  ASSERT_EQ(sum.branch_positions.size(), 2u);
  const double above = std::max(sum.branch_positions[0][1], sum.branch_positions[1][1]);
  const double below = std::min(sum.branch_positions[0][1], sum.branch_positions[1][1]);
  EXPECT_GT(above, notch[1] + 2 * kDx);
  EXPECT_LT(below, notch[1] - 2 * kDx);
  for (const auto& c : sum.branch_positions) EXPECT_GT(c[0], fork[0]);
}

TEST(CrackMeasure, DamageNotConnectedToTheNotchTipIsIgnored) {
  ParticleStore p = plate(0.135, 0.085, kDx);
  // A blob farther from the notch than the crack: it would be the tip if it counted.
  paint_segment(p, {0.11, 0.02, 0}, {0.11, 0.02, 0}, 6 * kDx);
  CrackTracker blob_only(one_tip(1));
  const auto empty = blob_only.measure(p, 0, 0.0).at(0);
  EXPECT_EQ(empty.distance, 0.0);
  EXPECT_EQ(empty.branches, 0);
  EXPECT_FALSE(blob_only.summary()[0].initiation_time.has_value());
  EXPECT_FALSE(blob_only.summary()[0].angle_deg.has_value());

  paint_segment(p, kNotch, kNotch + 40 * kDx * unit(30), 0.75 * kDx);
  CrackTracker tracker(one_tip(1));
  const auto row = tracker.measure(p, 0, 0.0).at(0);
  EXPECT_NEAR(row.distance, 40 * kDx, kDx);
  EXPECT_NEAR(row.angle_deg, 30.0, 1.5);
  EXPECT_EQ(row.branches, 1);
  const auto graph = damage_graph(p, 0.35);
  const auto crack = crack_path(graph, p, kNotch);
  std::size_t in_crack = 0;
  for (std::size_t n = 0; n < crack.path.size(); ++n) {
    if (!std::isfinite(crack.path[n])) continue;
    EXPECT_LT(p.reference_position[0][graph.particle[n]], 0.05);  // none of the blob
    ++in_crack;
  }
  EXPECT_GT(in_crack, 40u);
  EXPECT_LT(in_crack, graph.size() - 100);  // the blob has about π·6² particles
}

TEST(CrackMeasure, TipIsTheFarthestAlongThePath) {
  // A crack that runs 30 Δx in +x, 10 Δx up and 25 Δx back: its end is 11 Δx from the notch in
  // a straight line, the corners are farther, but the end is farthest along the crack.
  ParticleStore p = plate(0.06, 0.03, kDx);
  const Vec3 a = kNotch + Vec3{0.03, 0, 0}, b = a + Vec3{0, 0.01, 0}, end = b - Vec3{0.025, 0, 0};
  paint_segment(p, kNotch, a, 0.75 * kDx);
  paint_segment(p, a, b, 0.75 * kDx);
  paint_segment(p, b, end, 0.75 * kDx);
  CrackTracker tracker(one_tip(1));
  const auto row = tracker.measure(p, 0, 0.0).at(0);
  EXPECT_NEAR(geometry::norm(row.x - end), 0.0, kDx);
  EXPECT_NEAR(row.distance, geometry::norm(end - kNotch), kDx);
  EXPECT_NEAR(row.path_length, 0.065, 3 * kDx);  // the band cuts the two corners
}

TEST(CrackMeasure, ThresholdSelectsTheDamagedSet) {
  ParticleStore p = plate(0.06, 0.03, kDx);
  paint_segment(p, kNotch, kNotch + Vec3{0.02, 0, 0}, 0.75 * kDx);
  for (auto& d : p.damage) d *= 0.3;  // below the default 0.35
  CrackTracker strict(one_tip(1));
  EXPECT_EQ(strict.measure(p, 0, 0.0).at(0).branches, 0);
  Settings loose = one_tip(1);
  loose.damage_threshold = 0.25;
  EXPECT_NEAR(CrackTracker(loose).measure(p, 0, 0.0).at(0).distance, 0.02, kDx);
}

TEST(CrackMeasure, FollowsAStoreThatIsRefinedBetweenMeasurements) {
  CrackTracker tracker(one_tip(1));
  ParticleStore coarse = plate(0.06, 0.04, kDx);
  paint_segment(coarse, kNotch, kNotch + 20 * kDx * unit(45), 0.75 * kDx);
  tracker.measure(coarse, 0, 0.0);
  ParticleStore fine = plate(0.06, 0.04, kDx / 2);  // four times the particles
  ASSERT_EQ(fine.size(), 4 * coarse.size());
  paint_segment(fine, kNotch, kNotch + 40 * kDx * unit(45), 0.4 * kDx);
  const auto row = tracker.measure(fine, 10, kInterval).at(0);
  EXPECT_NEAR(row.distance, 40 * kDx, 0.5 * kDx);
  EXPECT_NEAR(row.speed, 20 * kDx / kInterval, 1.5 * kDx / kInterval);
  EXPECT_NEAR(row.angle_deg, 45.0, 1.0);
}

TEST(CrackMeasure, LinksJoinNeighboursAndDiagonalsOnly) {
  ParticleStore p = plate(0.01, 0.01, kDx);
  p.damage.assign(p.size(), 1.0);
  const auto g = damage_graph(p, 0.35);
  ASSERT_EQ(g.size(), 100u);
  std::size_t links = 0;
  for (std::size_t n = 0; n < g.size(); ++n)
    for (auto l = g.offset[n]; l < g.offset[n + 1]; ++l) {
      EXPECT_LE(g.length[l], 1.5 * kDx);
      ++links;
    }
  // 10 x 10 lattice: 2·9·10 axis pairs and 2·9·9 diagonal pairs, each listed from both ends.
  EXPECT_EQ(links, 2u * (2 * 9 * 10 + 2 * 9 * 9));
}

TEST(CrackMeasure, AngleAndRayleighSpeed) {
  EXPECT_NEAR(angle_between_deg({1, 0, 0}, {1, 1, 0}), 45.0, 1e-12);
  EXPECT_NEAR(angle_between_deg({1, 0, 0}, {-1, -1e-9, 0}), 180.0, 1e-6);
  EXPECT_TRUE(std::isnan(angle_between_deg({1, 0, 0}, {0, 0, 0})));
  ParticleStore p = plate(0.02, 0.01, kDx);
  for (std::size_t i = 0; i < p.size(); ++i) p.material[i] = p.reference_position[0][i] > 0.01;
  const std::vector<Material> materials{{72e9, 2440, 1}, {200e9, 7800, 1}};
  const Section s = plane_stress();
  EXPECT_EQ(rayleigh_speed_near(p, materials, s, {0.004, 0.005, 0}),
            rayleigh_speed(materials[0], s));
  EXPECT_EQ(rayleigh_speed_near(p, materials, s, {0.016, 0.005, 0}),
            rayleigh_speed(materials[1], s));
}

// ---- the `measure` block of a scene ----

const std::string kMeasured = std::string(scene::samples::kMinimal) + R"(effects: {fracture: true}
measure:
  damage_threshold: 0.5
  every: 4
  smoothing: 2
  branch_separation: 3
  tips:
    - {name: upper, at: [0.5, 0.7], direction: [1, 1]}
    - {name: lower, at: [0.5, 0.3], direction: [1, -1]}
  published: {upper: {angle_deg: 65.7, branch_times: [2.45e-5, 3e-5]}, particles_end: 54860}
)";

TEST(MeasureScene, ReadsAndResolvesTheBlock) {
  const auto check = [](const scene::Scene& s) {
    ASSERT_TRUE(s.measure.has_value());
    const auto& m = s.measure->settings;
    EXPECT_EQ(m.damage_threshold, 0.5);
    EXPECT_EQ(m.every, 4);
    EXPECT_EQ(m.smoothing, 2);
    EXPECT_EQ(m.branch_separation, 3.0);
    ASSERT_EQ(m.tips.size(), 2u);
    EXPECT_EQ(m.tips[1].name, "lower");
    EXPECT_EQ(m.tips[1].at, (Vec3{0.5, 0.3, 0}));
    EXPECT_EQ(m.tips[1].direction, (Vec3{1, -1, 0}));
    const auto& pub = *s.measure->published;
    ASSERT_EQ(pub.keys, (std::vector<std::string>{"upper", "particles_end"}));
    EXPECT_EQ(pub.values[0].values[0].number, 65.7);
    EXPECT_EQ(pub.values[0].values[1].list, (std::vector<double>{2.45e-5, 3e-5}));
    EXPECT_TRUE(pub.values[1].integer);
    EXPECT_EQ(pub.values[1].number, 54860);
  };
  const auto s = scene::parse_scene(kMeasured, "m.yaml");
  check(s);
  check(scene::parse_scene(scene::resolved_yaml(s), "resolved.yaml"));
  const auto defaults =
      scene::parse_scene(kMeasured.substr(0, kMeasured.find("measure:")) +
                             "measure: {tips: [{name: a, at: [0.5, 0.5], direction: [1, 0]}]}\n",
                         "d.yaml");
  EXPECT_EQ(defaults.measure->settings.damage_threshold, 0.35);
  EXPECT_EQ(defaults.measure->settings.every, 10);
  EXPECT_EQ(defaults.measure->settings.smoothing, 1);
  EXPECT_EQ(defaults.measure->settings.branch_separation, 2.0);
  EXPECT_FALSE(defaults.measure->published.has_value());
}

TEST(MeasureScene, ATipsRegionIsReadAndResolved) {
  const std::string text =
      kMeasured.substr(0, kMeasured.find("measure:")) +
      "measure: {tips: [{name: a, at: [0.5, 0.5], direction: [1, 0], region: {shape: "
      "half-space, point: [0, 0.5], normal: [0, -1]}}]}\n";
  const auto s = scene::parse_scene(text, "r.yaml");
  const auto& tip = s.measure->settings.tips.at(0);
  ASSERT_TRUE(tip.region.has_value());
  EXPECT_TRUE(tip.region->contains({0.9, 0.7, 0}, 2));
  EXPECT_FALSE(tip.region->contains({0.9, 0.3, 0}, 2));
  const std::string resolved = scene::resolved_yaml(s);
  EXPECT_NE(resolved.find("region: {shape: half-space, point: [0, 0.5], normal: [0, -1]}"),
            std::string::npos)
      << resolved;
  EXPECT_EQ(scene::resolved_yaml(scene::parse_scene(resolved, "again.yaml")), resolved);
}

TEST(MeasureScene, TipOutsideTheBodyIsRefusedBeforeTheRun) {
  const auto s = scene::parse_scene(kMeasured, "m.yaml", {{"measure.tips.1.at", "[0.5, 1.2]"}});
  try {
    scene::build_simulation(s);
    FAIL() << "accepted a notch tip outside the body";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--set measure.tips.1.at: the notch tip [0.5, 1.2] lies "
                                         "outside the body's bounding box (allowed: [0, 0] to "
                                         "[1, 1])"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(scene::build_simulation(scene::parse_scene(kMeasured, "m.yaml")));
}

TEST(CrackMeasure, ThroughTheThicknessOfA3DPlateTheFrontIsNotABranch) {
  // A 12 x 10 x 8 mm block (1 mm spacing, δ = 3 mm): damage runs from a notch front along z,
  // ahead only at the two faces (z = 0.5 and 7.5 mm, 7 mm > 2δ apart) as in a 3D plate whose
  // faces crack first. Without `front` those are two branches; along the front they are one.
  geometry::Box box;
  box.max = {0.012, 0.01, 0.008};
  Section s3;
  s3.dim = 3;
  auto p = test::store_from_points(geometry::fill_lattice({{box, kDx, 0}}, 3), 3, kFactor, s3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x = p.reference_position[0][i], y = p.reference_position[1][i];
    const double z = p.reference_position[2][i];
    const bool layer = std::abs(y - 0.0045) < 1e-6;
    const bool front = std::abs(x - 0.0025) < 1e-6, face = z < 0.001 || z > 0.007;
    if (layer && x > 0.002 && (front || face)) p.damage[i] = 1.0;
  }
  for (const bool along_front : {false, true}) {
    Settings s;
    Tip tip{"notch", {0.0025, 0.0045, 0.0035}, {1, 0, 0}, std::nullopt, std::nullopt};
    if (along_front) tip.front = Vec3{0, 0, 1};
    s.tips = {tip};
    CrackTracker tracker(s);
    const auto rows = tracker.measure(p, 0, 0.0);
    EXPECT_EQ(rows.at(0).branches, along_front ? 1 : 2);
  }
}

TEST(CrackMeasure, ARegionKeepsAnotherNotchsCrackOutOfThisOne) {
  // Two notch tips 20 mm apart (y = 35 and 15 mm), each with a crack at ±60°, joined by damage
  // between the notches (an impact zone): without regions each tip's crack runs through it into
  // the other crack (path 10 + 20 + 12 mm against 12 mm), so the tip is found on the wrong one;
  // with the half-spaces above and below the notch lines each tip finds its own crack.
  ParticleStore p = plate(0.04, 0.05, kDx);
  const Vec3 upper{0.01, 0.035, 0}, lower{0.01, 0.015, 0};
  paint_segment(p, upper, upper + 0.012 * unit(60), 0.75 * kDx);
  paint_segment(p, lower, lower + 0.012 * unit(-60), 0.75 * kDx);
  paint_segment(p, upper, lower, 0.75 * kDx);  // the damaged zone between the notch tips
  paint_segment(p, lower, {0.0, 0.015, 0}, 0.75 * kDx);
  for (const bool regions : {false, true}) {
    Settings s;
    s.tips = {{"upper", upper, {1, 0, 0}, std::nullopt, std::nullopt},
              {"lower", lower, {1, 0, 0}, std::nullopt, std::nullopt}};
    if (regions) {
      s.tips[0].region = geometry::Shape::half_space({0, 0.035, 0}, {0, -1, 0});
      s.tips[1].region = geometry::Shape::half_space({0, 0.015, 0}, {0, 1, 0});
    }
    CrackTracker tracker(s);
    const auto rows = tracker.measure(p, 0, 0.0);
    if (regions) {
      EXPECT_NEAR(rows.at(0).angle_deg, 60.0, 5.0);
      EXPECT_GT(rows.at(0).x[1], upper[1]);
      EXPECT_NEAR(rows.at(1).angle_deg, 60.0, 5.0);
      EXPECT_LT(rows.at(1).x[1], lower[1]);
    } else {
      EXPECT_LT(rows.at(0).x[1], lower[1]);  // the upper tip found on the lower crack
    }
  }
}

TEST(CrackMeasure, AFrontMeasuresTheAngleInThePlateNotTheTipsHeight) {
  // A short crack at 60° in a 3D plate whose farthest particles lie at the plate's face, 3.5 mm
  // above the notch tip's height: with `front` the angle is the crack's, about 60°; without, the
  // chord through the thickness tilts it (height 3.5 mm over about 4 mm in the plate).
  geometry::Box box;
  box.max = {0.02, 0.02, 0.008};
  Section s3;
  s3.dim = 3;
  auto p = test::store_from_points(geometry::fill_lattice({{box, kDx, 0}}, 3), 3, kFactor, s3);
  const Vec3 notch{0.0025, 0.0025, 0.004};
  const Vec3 along = unit(60);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 x{p.reference_position[0][i], p.reference_position[1][i],
                 p.reference_position[2][i]};
    const Vec3 d = x - notch;
    const Vec3 in_plane{d[0], d[1], 0};
    const double t = std::clamp(geometry::dot(in_plane, along), 0.0, 0.0045);
    if (geometry::norm(in_plane - t * along) <= 0.75 * kDx && (t < 0.003 || x[2] > 0.007))
      p.damage[i] = 1.0;
  }
  for (const bool with_front : {false, true}) {
    Settings s;
    Tip tip{"notch", notch, {1, 0, 0}, std::nullopt, std::nullopt};
    if (with_front) tip.front = Vec3{0, 0, 1};
    s.tips = {tip};
    CrackTracker tracker(s);
    const TipRow r = tracker.measure(p, 0, 0.0).at(0);
    ASSERT_GT(r.x[2], 0.007);  // the farthest particle sits at the face
    const Vec3 d = r.x - notch;
    const double in_plane = std::atan2(d[1], d[0]) * 180.0 / std::numbers::pi;
    EXPECT_NEAR(in_plane, 60.0, 5.0);
    if (with_front) {
      EXPECT_NEAR(r.angle_deg, in_plane, 1e-9);
    } else {
      EXPECT_GT(r.angle_deg, in_plane + 5.0);
    }
  }
}

}  // namespace
}  // namespace dhpd::measure
