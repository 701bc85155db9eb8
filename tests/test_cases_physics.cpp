// The shipped paper cases that are cheap enough for every test run, each with the numbers the
// issue asks for (IJNME 2016 §5.2–5.3; Ha & Bobaru 2010; Bobaru & Zhang 2015). The 3D and
// uniform-fine cases run by hand or through `dhpd study` (README).
#include "tests/cli_support.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class PaperCase : public CliTest {
 protected:
  /// Runs cases/NAME.yaml in full and returns its summary.json.
  json run_case(const std::string& name) {
    const auto o =
        dhpd({"run", std::string(DHPD_SOURCE_DIR) + "/cases/" + name + ".yaml", "-o", name, "-q"});
    EXPECT_EQ(o.code, 0) << o.err;
    return read_json(dir_ / name / "summary.json");
  }
  static double first_branch(const json& crack) {
    const auto& times = crack.at("branch_times");
    return times.empty() ? -1.0 : times.front().get<double>();
  }
};

TEST_F(PaperCase, KalthoffWinkler2dAnglesInitiationAndSpeed) {
  const auto s = run_case("kalthoff_winkler_2d_uniform");
  const double c_r = s.at("rayleigh_speed").get<double>();
  ASSERT_EQ(s.at("cracks").size(), 2u);
  for (const auto& crack : s.at("cracks")) {
    const double angle = crack.at("angle_deg").get<double>();
    const double t0 = crack.at("initiation_time").get<double>();
    std::printf("KW 2D %s: angle %.1f deg, initiation %.1f us, max speed %.0f m/s (c_R %.0f)\n",
                crack.at("name").get<std::string>().c_str(), angle, t0 * 1e6,
                crack.at("max_speed").get<double>(), c_r);
    EXPECT_GE(angle, 60.0);  // published 65.7° (uniform), experiment about 70°
    EXPECT_LE(angle, 72.0);
    EXPECT_NEAR(t0, 26e-6, 0.15 * 26e-6);
    EXPECT_LT(crack.at("max_speed").get<double>(), c_r);
  }
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
  EXPECT_NEAR(t_uniform, 24.5e-6, 0.2 * 24.5e-6);   // IJNME 2016 §5.3.2, uniform
  EXPECT_NEAR(t_adaptive, 19.4e-6, 0.2 * 19.4e-6);  // IJNME 2016 §5.3.2, adaptive
  EXPECT_NEAR(t_bz, t_uniform, 0.05 * t_uniform);   // same load over bond strength
  for (const json* s : {&ijnme, &bz, &adaptive})
    EXPECT_LT(s->at("cracks")[0].at("max_speed").get<double>(),
              s->at("rayleigh_speed").get<double>());
}

}  // namespace
