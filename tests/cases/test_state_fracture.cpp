// The state-based family breaking bonds on the paper cases (docs/theory.md §20.4): Kalthoff–Winkler
// 2D at 0.78 mm with steel's ν = 0.3 and the branching plate with glass's ν = 0.22, each beside its
// bond-based run (ν fixed at 1/4 and 1/3). The numbers: docs/verification.md, "State-based
// fracture".
#include <cstdio>
#include <string>
#include <vector>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class StateFractureCase : public CliTest {
 protected:
  json run_case(const std::string& name, const std::string& out,
                const std::vector<std::string>& overrides) {
    const auto o = dhpd({"run", std::string(DHPD_SOURCE_DIR) + "/cases/" + name + ".yaml", "-o",
                         out, "-q", "--overwrite"},
                        overrides);
    EXPECT_EQ(o.code, 0) << o.err;
    return read_json(dir_ / out / "summary.json");
  }
  static std::vector<std::string> state_based(const std::string& material, double nu) {
    return {"model={family: ordinary-state, horizon: dual-horizon}",
            "materials." + material + ".nu=" + std::to_string(nu)};
  }
};

TEST_F(StateFractureCase, KalthoffWinklerWithSteelsPoissonsRatio) {
  const auto bond = run_case("kalthoff_winkler_2d_uniform_fine", "bond", {});
  const auto state =
      run_case("kalthoff_winkler_2d_uniform_fine", "state", state_based("steel", 0.3));
  ASSERT_EQ(state.at("cracks").size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    const auto& s = state.at("cracks")[c];
    const auto& b = bond.at("cracks")[c];
    const double angle = s.at("angle_deg").get<double>();
    const double t = s.at("initiation_time").get<double>(),
                 tb = b.at("initiation_time").get<double>();
    std::printf(
        "KW 2D %s: state-based (nu 0.3) angle %.1f deg, initiation %.2f us; bond-based "
        "%.1f deg, %.2f us\n",
        s.at("name").get<std::string>().c_str(), angle, t * 1e6, b.at("angle_deg").get<double>(),
        tb * 1e6);
    EXPECT_GE(angle, 60.0);  // measured 66.5 deg; the paper's 66.5, the experiment's about 70
    EXPECT_LE(angle, 72.0);
    EXPECT_NEAR(t, tb, 0.2 * tb);
  }
  // The back face does not spall: about as many bonds break as in the bond-based run (a critical
  // stretch 0.81 times lower, from the energy released instead of held, broke twice as many).
  const double broken = state.at("broken_bonds").get<double>();
  EXPECT_LT(broken, 1.3 * bond.at("broken_bonds").get<double>());
}

TEST_F(StateFractureCase, BranchingPlateWithGlasssPoissonsRatio) {
  const auto bond = run_case("branching_plate_uniform", "bond", {});
  const auto state = run_case("branching_plate_uniform", "state", state_based("glass", 0.22));
  const auto& s = state.at("cracks")[0];
  const auto& b = bond.at("cracks")[0];
  ASSERT_FALSE(s.at("branch_times").empty());
  const double tb = s.at("branch_times")[0].get<double>();
  const double tb_bond = b.at("branch_times")[0].get<double>();
  const double t0 = s.at("initiation_time").get<double>();
  const double t0_bond = b.at("initiation_time").get<double>();
  std::printf(
      "branching plate: state-based (nu 0.22) initiation %.2f us, first branching %.2f us; "
      "bond-based %.2f us, %.2f us\n",
      t0 * 1e6, tb * 1e6, t0_bond * 1e6, tb_bond * 1e6);
  EXPECT_NEAR(t0, t0_bond, 0.15 * t0_bond);
  EXPECT_NEAR(tb, tb_bond, 0.15 * tb_bond);
}

}  // namespace
