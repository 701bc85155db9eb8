// The shipped paper cases that are cheap enough for every test run, each with the numbers the
// issue asks for (IJNME 2016 §5.2–5.3; Ha & Bobaru 2010; Bobaru & Zhang 2015). The 3D and
// uniform-fine cases run by hand or through `dhpd study` (docs/verification.md).
#include <algorithm>
#include <string>
#include <vector>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class PaperCase : public CliTest {
 protected:
  /// Runs cases/NAME.yaml in full (with --set OVERRIDES) and returns its summary.json.
  json run_case(const std::string& name, const std::vector<std::string>& overrides = {}) {
    const auto o = dhpd({"run", std::string(DHPD_SOURCE_DIR) + "/cases/" + name + ".yaml", "-o",
                         name, "-q", "--overwrite"},
                        overrides);
    EXPECT_EQ(o.code, 0) << o.err;
    return read_json(dir_ / name / "summary.json");
  }
  static double first_branch(const json& crack) {
    const auto& times = crack.at("branch_times");
    return times.empty() ? -1.0 : times.front().get<double>();
  }
};

TEST_F(PaperCase, KalthoffWinkler2dAnglesInitiationAndSpeed) {
  // The final angle of a crack that crosses the plate is chaotic in the time step: runs 5 % apart
  // in dt end 58–75° (docs/verification.md). The paper's number is a claim about where the angle
  // lies, so it is checked on the median of runs at eight safeties; initiation and speed hold in
  // every run.
  std::vector<double> angles;
  for (int k = 0; k < 8; ++k) {
    const std::string safety = std::to_string(0.3 + 0.05 * k).substr(0, 4);
    const auto s = run_case("kalthoff_winkler_2d_uniform", {"time.safety=" + safety});
    const double c_r = s.at("rayleigh_speed").get<double>();
    ASSERT_EQ(s.at("cracks").size(), 2u);
    for (const auto& crack : s.at("cracks")) {
      const double angle = crack.at("angle_deg").get<double>();
      const double t0 = crack.at("initiation_time").get<double>();
      std::printf(
          "KW 2D safety %s %s: angle %.1f deg, initiation %.1f us, max speed %.0f m/s "
          "(c_R %.0f)\n",
          safety.c_str(), crack.at("name").get<std::string>().c_str(), angle, t0 * 1e6,
          crack.at("max_speed").get<double>(), c_r);
      angles.push_back(angle);
      EXPECT_GE(angle, 50.0);  // no run turns back to the notch line or straight down
      EXPECT_LE(angle, 80.0);
      EXPECT_NEAR(t0, 26e-6, 0.15 * 26e-6);
      EXPECT_LT(crack.at("max_speed").get<double>(), c_r);
    }
  }
  std::sort(angles.begin(), angles.end());
  const double median = 0.5 * (angles[angles.size() / 2 - 1] + angles[angles.size() / 2]);
  std::printf("KW 2D: median angle %.1f deg over %zu crack ends\n", median, angles.size());
  EXPECT_GE(median, 60.0);  // published 65.7° (uniform), experiment about 70°
  EXPECT_LE(median, 72.0);
}

TEST_F(PaperCase, KalthoffWinklerInitialVelocityBreaksNothing) {
  // The papers' stated load, an initial velocity of the first three layers, carries too little
  // energy for any crack; the held velocity of the other cases breaks (cases' headers).
  const auto initial = run_case("kalthoff_winkler_2d_initial_velocity");
  const auto held = run_case("kalthoff_winkler_2d_uniform");
  std::printf("Kalthoff-Winkler 2D: %lld bonds broken with an initial velocity, %lld held\n",
              initial.at("broken_bonds").get<long long>(),
              held.at("broken_bonds").get<long long>());
  EXPECT_EQ(initial.at("broken_bonds").get<long long>(), 0);
  EXPECT_GT(held.at("broken_bonds").get<long long>(), 1000);
}

TEST_F(PaperCase, BranchingPlateBranchesAndBothParameterSetsAgree) {
  const auto ijnme = run_case("branching_plate_uniform");
  const auto bz = run_case("branching_plate_bobaru_zhang");
  const auto adaptive = run_case("branching_plate_adaptive");
  const double t_uniform = first_branch(ijnme.at("cracks")[0]);
  const double t_bz = first_branch(bz.at("cracks")[0]);
  const double t_adaptive = first_branch(adaptive.at("cracks")[0]);
  std::printf("branching: uniform %.2f us, Bobaru-Zhang %.2f us, adaptive %.2f us\n",
              t_uniform * 1e6, t_bz * 1e6, t_adaptive * 1e6);
  EXPECT_NEAR(t_uniform, 24.5e-6, 0.2 * 24.5e-6);  // IJNME 2016 §5.3.2, uniform
  // The paper's adaptive plate branches at 19.4 µs, 21 % before its uniform one; ours follows
  // its uniform 0.5 mm plate (docs/verification.md: the paper's copy mapping).
  EXPECT_NEAR(t_adaptive, t_uniform, 0.05 * t_uniform);
  EXPECT_NEAR(t_bz, t_uniform, 0.05 * t_uniform);  // same load over bond strength
  for (const json* s : {&ijnme, &bz, &adaptive})
    EXPECT_LT(s->at("cracks")[0].at("max_speed").get<double>(),
              s->at("rayleigh_speed").get<double>());
}

TEST_F(PaperCase, AdaptivePlateRefinesItsNotchTipBeforeABondBreaks) {
  // Children inherit their parent's broken bonds (no healing): a tip refined after its first bonds
  // broke starts its crack at that event. The case's stretch trigger refines in time, and the
  // adaptive initiation then follows the uniform 0.5 mm plate's; without it (damage and energy
  // only) the first event starts bonds broken and "initiates" the crack itself.
  const std::string cases = std::string(DHPD_SOURCE_DIR) + "/cases/";
  const auto first_event = [&](const std::string& out) {
    const auto csv = read_history(dir_ / out / "refinement.csv");  // CSV with a header
    const auto column = [&](const std::string& name) {
      const auto at = csv.header.find(name);
      return static_cast<std::size_t>(std::count(csv.header.begin(), csv.header.begin() + at, ','));
    };
    return std::pair{std::stod(csv.rows.at(0).at(column("time"))),
                     std::stoll(csv.rows.at(0).at(column("started_broken")))};
  };
  const auto initiation = [&](const std::string& out) {
    return read_json(dir_ / out / "summary.json")
        .at("cracks")[0]
        .at("initiation_time")
        .get<double>();
  };
  ASSERT_EQ(dhpd({"run", cases + "branching_plate_uniform.yaml", "-o", "uniform", "-q"},
                 {"time.end=9e-6"})
                .code,
            0);
  ASSERT_EQ(dhpd({"run", cases + "branching_plate_adaptive.yaml", "-o", "stretch", "-q"},
                 {"time.end=9e-6"})
                .code,
            0);
  ASSERT_EQ(dhpd({"run", cases + "branching_plate_adaptive.yaml", "-o", "late", "-q"},
                 {"time.end=9e-6", "effects.refinement.trigger={damage: 0.05, energy: 0.5}"})
                .code,
            0);
  const auto [t_stretch, broken_stretch] = first_event("stretch");
  const auto [t_late, broken_late] = first_event("late");
  const double uniform = initiation("uniform");
  std::printf(
      "first event %.2f us (%lld started broken), initiation %.2f us; without the stretch "
      "trigger %.2f us (%lld), %.2f us; uniform 0.5 mm %.2f us\n",
      t_stretch * 1e6, static_cast<long long>(broken_stretch), initiation("stretch") * 1e6,
      t_late * 1e6, static_cast<long long>(broken_late), initiation("late") * 1e6, uniform * 1e6);
  EXPECT_EQ(broken_stretch, 0);  // measured: 5.15 µs, none; initiation 7.11 µs (uniform 7.30)
  EXPECT_NEAR(initiation("stretch"), uniform, 0.05 * uniform);
  EXPECT_GT(broken_late, 0);  // measured: 6.87 µs, 92; the crack "starts" at that step
  EXPECT_NEAR(initiation("late"), t_late, 1e-12);
}

}  // namespace
