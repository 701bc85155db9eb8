// When the branching plate's notch starts to run, against linear elastic fracture mechanics:
// Freund's suddenly loaded semi-infinite crack (Dynamic Fracture Mechanics, 1990, §2.5). The two
// tensile waves from the loaded edges meet on the crack plane, so its faces see p = 2σ from the
// moment the waves arrive; LEFM's initiation is that arrival plus the time K_I needs to reach
// sqrt(E G0). As the horizon shrinks, the peridynamic initiation must converge to it.
#include <cmath>
#include <cstdio>

#include "tests/support/cli.hpp"
#include "tests/support/lefm.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

const dhpd::Material kGlass{72.0e9, 2440.0, 135.0};  // cases/branching_plate_uniform.yaml
const dhpd::Section kPlaneStress{2, dhpd::PlaneMode::Stress, 0.001, 1.0};

class NotchInitiation : public CliTest {
 protected:
  /// Initiation time of the branching plate at spacing dx, measured at every step.
  double initiation_at(double dx) {
    const std::string out = "dx" + std::to_string(dx);
    const auto o = dhpd(
        {"run", std::string(DHPD_SOURCE_DIR) + "/cases/branching_plate_uniform.yaml", "-o", out,
         "-q", "--set", "body.0.spacing=" + std::to_string(dx), "--set", "time.end=9e-6", "--set",
         "measure.every=1", "--set", "output.frames=1", "--set", "output.history_every=1000"});
    EXPECT_EQ(o.code, 0) << o.err;
    const auto s = read_json(dir_ / out / "summary.json");
    const auto& t = s.at("cracks")[0].at("initiation_time");
    return t.is_null() ? NAN : t.get<double>();
  }
};

TEST_F(NotchInitiation, BranchingPlateConvergesToFreundAsTheHorizonShrinks) {
  // The tractions act on the rows within 1.5 mm of each edge: the waves start 0.75 mm inside and
  // run 19.25 mm to the crack plane.
  const double arrival = 0.01925 / dhpd::lefm::dilatational_speed(kGlass, kPlaneStress);
  const double delay = dhpd::lefm::initiation_delay(kGlass, kPlaneStress, 2 * 12e6);
  const double t_lefm = arrival + delay;  // 3.34 + 2.59 µs
  const double t1 = initiation_at(0.001), t2 = initiation_at(0.0005), t3 = initiation_at(0.00025);
  // Richardson: the differences shrink by r per halving; the rest of the series is d r / (1 − r).
  const double r = (t2 - t3) / (t1 - t2);
  const double t_limit = t3 - (t2 - t3) * r / (1.0 - r);
  std::printf(
      "initiation: dx 1 / 0.5 / 0.25 mm: %.3f / %.3f / %.3f us; ratio %.2f; "
      "extrapolated %.3f us; LEFM %.3f us (%.3f + %.3f)\n",
      t1 * 1e6, t2 * 1e6, t3 * 1e6, r, t_limit * 1e6, t_lefm * 1e6, arrival * 1e6, delay * 1e6);
  // Converging from above: each finer horizon starts earlier, all after LEFM's K_Ic moment.
  EXPECT_GT(t3, t_lefm);
  EXPECT_LT(t3, t2);
  EXPECT_LT(t2, t1);
  EXPECT_GT(r, 0.0);
  EXPECT_LT(r, 0.9);
  // The limit is LEFM's: within 15 % of the time K_I needs (a bond strength off by √2, i.e.
  // G0 off by 2, moves it by 50 %).
  EXPECT_NEAR(t_limit, t_lefm, 0.15 * delay);
}

}  // namespace
