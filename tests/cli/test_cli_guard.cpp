// Input that would make a run unstable is refused at load time (coincident particles, an empty
// horizon, a fixed dt above the stable one unless the check is off), and an unstable run keeps its
// last good state as its final frame and checkpoint (exit 3).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/cli.hpp"
#include "tests/support/statics.hpp"
#include "tests/support/vtk_read.hpp"

namespace dhpd {
namespace cli_test {
namespace {

constexpr const char* kPoints = R"(name: points
dimension: 2
plane: stress
thickness: 0.001
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
body:
  - {points_file: pts.txt, material: glass}
time: {steps: 10}
)";

std::string grid_points(int n, double h) {
  std::string text;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      text += fmt::format("{} {} {}\n", (i + 0.5) * h, (j + 0.5) * h, h * h * 1e-3);
  return text;
}

TEST_F(CliTest, CoincidentParticlesAreRefusedAtLoadTime) {
  write("scene.yaml", kPoints);
  write("pts.txt", grid_points(6, 1e-3) + "0.0025 0.0035 1e-9\n");
  const auto o = dhpd({"run", "scene.yaml", "-o", "out", "-q"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("scene.yaml:8: body.0: two particles coincide at [0.0025, 0.0035]"),
            std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(CliTest, AParticleWithAnEmptyHorizonIsRefusedAtLoadTime) {
  write("scene.yaml", kPoints);
  write("pts.txt", grid_points(6, 1e-3) + "0.05 0.05 1e-9\n");
  const auto o = dhpd({"check", "scene.yaml"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find("scene.yaml:8: body.0: the particle at [0.05, 0.05] has no neighbour"),
            std::string::npos)
      << o.err;
  write("pts.txt", grid_points(6, 1e-3));
  EXPECT_EQ(dhpd({"check", "scene.yaml"}).code, 0);
}

constexpr const char* kBar = R"(name: bar
dimension: 1
area: 1.0e-4
materials:
  rod: {E: 7.0e10, rho: 2700}
body:
  - {shape: box, min: [0.0], max: [0.1], spacing: 0.001, material: rod}
initial_conditions:
  - region: {shape: box, min: [0.0], max: [0.1]}
    velocity: [1.0]
    gaussian: {center: [0.05], width: 0.005}
time: {steps: 400}
output: {frames: 4, history_every: 10}
)";

TEST_F(CliTest, FixedDtAboveStableRunsOnlyWithCheckOffAndStopsWithExitThree) {
  write("bar.yaml", kBar);
  const auto check = dhpd({"check", "bar.yaml"});
  ASSERT_EQ(check.code, 0) << check.err;
  const auto at = check.out.find("stable_step: {run: ");  // the step the run would take
  ASSERT_NE(at, std::string::npos) << check.out;
  const double stable = std::stod(check.out.substr(at + 19));
  const std::string dt = fmt::format("time.dt={:.17g}", 1.5 * stable);
  const auto refused = dhpd({"run", "bar.yaml", "-o", "refused", "-q"}, {dt});
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("time.check_dt: false"), std::string::npos) << refused.err;
  const auto o = dhpd({"run", "bar.yaml", "-o", "out", "-q"}, {dt, "time.check_dt=false"});
  EXPECT_EQ(o.code, 3) << o.err;
  EXPECT_NE(o.err.find("1.5 x the stable step"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("id "), std::string::npos) << o.err;
  const auto summary = read_json(dir_ / "out" / "summary.json");
  EXPECT_EQ(summary.at("status"), "unstable");
  EXPECT_LT(summary.at("steps").get<long long>(), 300);
  // The same scene at the stable step completes.
  EXPECT_EQ(dhpd({"run", "bar.yaml", "-o", "fine", "-q"}).code, 0);
}

/// "... the last good state (step N, ..." of an unstable run's message; -1 when absent.
long long last_good_step(const std::string& err) {
  const auto at = err.find("the last good state (step ");
  return at == std::string::npos ? -1 : std::stoll(err.substr(at + 26));
}

long long failing_step(const std::string& err) {
  const auto at = err.find("at step ");
  return at == std::string::npos ? -1 : std::stoll(err.substr(at + 8));
}

TEST_F(CliTest, UnstableRunKeepsItsLastGoodStateAsFinalFrameAndCheckpoint) {
  write("bar.yaml", kBar);
  const auto check = dhpd({"check", "bar.yaml"});
  const double stable = std::stod(check.out.substr(check.out.find("stable_dt: ") + 11));
  // Just above the true limit (check's stable_dt is the per-particle bound (9.1), ~17 %
  // conservative in 1D; the run's default Lanczos step is not): the highest mode grows
  // slowly, so the run gets past step 100 before the guard stops it.
  const std::vector<std::string> sets{fmt::format("time.dt={:.17g}", 1.18 * stable),
                                      "time.check_dt=false", "time.steps=3000"};
  const auto o = dhpd({"run", "bar.yaml", "-o", "out", "-q"}, sets);
  ASSERT_EQ(o.code, 3) << o.err;
  const long long good = last_good_step(o.err), failed = failing_step(o.err);
  EXPECT_GE(good, 100) << o.err;
  EXPECT_EQ(good % 100, 0) << o.err;
  EXPECT_GT(failed, good) << o.err;
  EXPECT_NE(o.err.find("written as the final frame"), std::string::npos) << o.err;
  // The final frame is the good state: the last .pvd entry is at its time, and the .pvd parses.
  const auto frames = io::read_pvd((dir_ / "out" / "bar.pvd").string());
  ASSERT_GE(frames.size(), 2u);
  EXPECT_NEAR(frames.back().first, static_cast<double>(good) * 1.18 * stable, 1e-12);
  for (std::size_t k = 1; k < frames.size(); ++k) EXPECT_GT(frames[k].first, frames[k - 1].first);
  // Its checkpoint restarts and, bit for bit the same run, fails again at the same step.
  const auto again = dhpd({"run", "bar.yaml", "-o", "again", "--restart", "out", "-q"}, sets);
  EXPECT_EQ(again.code, 3) << again.err;
  EXPECT_EQ(failing_step(again.err), failed) << again.err;
}

// A static run refined between the relaxations of its load steps, stopped in a load step after
// several events in it (too many break rounds): its last good state is the load step before,
// restored from the guard's copy across those events, and its checkpoint fails again the same way.
TEST_F(CliTest, StaticAdaptiveRunStoppedAfterEventsKeepsTheLoadStepBefore) {
  write("notched.yaml",
        test::notched_plate(0.001, "{fracture: true, refinement: true}", ", max_break_rounds: 3"));
  const auto o = dhpd({"run", "notched.yaml", "-o", "out", "-q"});
  ASSERT_EQ(o.code, 3) << o.err;
  EXPECT_EQ(o.err.find("could not be restored"), std::string::npos) << o.err;
  const auto failed = o.err.find("relaxations in load step ");
  ASSERT_NE(failed, std::string::npos) << o.err;
  const long long step = std::stoll(o.err.substr(failed + 25));
  EXPECT_EQ(last_good_step(o.err), step - 1) << o.err;
  // refinement.csv: events in the failing load step, numbered by it (column `step`).
  const auto csv = read_text(dir_ / "out" / "refinement.csv");
  EXPECT_NE(csv.find(fmt::format("\n2,{},", step)), std::string::npos) << csv;
  const auto again = dhpd({"run", "notched.yaml", "-o", "again", "--restart", "out", "-q"});
  EXPECT_EQ(again.code, 3) << again.err;
  EXPECT_NE(again.err.find(fmt::format("relaxations in load step {} ", step)), std::string::npos)
      << again.err;
}

}  // namespace
}  // namespace cli_test
}  // namespace dhpd
