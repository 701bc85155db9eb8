// End-to-end: `dhpd stress` (the stability suite) on small suites of the cases/stress/ scenes, and
// each of its criteria shown able to fail, on real runs (ghost forces of classical-variable) and
// on doctored outputs checked with `dhpd stress --check`.
#include <fmt/format.h>

#include <cmath>

#include "tests/support/cli.hpp"
#include "tools/output/vtk_writer.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

const std::string kStressCases = std::string(DHPD_SOURCE_DIR) + "/cases/stress/";

class CliStress : public CliTest {
 protected:
  /// A suite of one case of cases/stress/ with `extra` lines added to the case entry.
  void write_suite(const std::string& scene, const std::string& extra = "") {
    write("suite.yaml",
          "name: mini\ncases:\n  - name: case\n    scene: " + kStressCases + scene + "\n" + extra);
  }

  /// Runs the 1D bar of cases/stress/ (0.3 s) with `threads` into `out`; expects exit 0.
  fs::path run_bar(const std::string& out, int threads, const std::vector<std::string>& sets = {}) {
    std::vector<std::string> args{"run",
                                  kStressCases + "horizon_ratio_1d.yaml",
                                  "-o",
                                  out,
                                  "-q",
                                  "--threads",
                                  std::to_string(threads)};
    const auto o = dhpd(args, sets);
    EXPECT_EQ(o.code, 0) << o.err;
    return dir_ / out;
  }

  /// `dhpd stress --check DIRS...`: its output lines and exit code.
  Outcome check(const std::vector<fs::path>& dirs) {
    std::vector<std::string> args{"stress", "--check"};
    for (const auto& d : dirs) args.push_back(d.string());
    return dhpd(args);
  }

  /// Rewrites every frame of `run` (same names, same order) with frame `which` (counted from
  /// the last: 0 is the last frame) changed by `change` (applied to its fields), keeping the .pvd.
  template <class Change>
  void doctor_last_frame(const fs::path& run, Change change, std::size_t which = 0) {
    std::vector<fs::path> frames;
    for (const auto& e : fs::directory_iterator(run))
      if (e.path().extension() == ".vtu") frames.push_back(e.path());
    std::sort(frames.begin(), frames.end());
    ASSERT_FALSE(frames.empty());
    const fs::path scratch = run / "rewritten";
    fs::create_directories(scratch);
    dhpd::io::FrameSeries series(scratch.string(), "horizon_ratio_1d");
    for (std::size_t k = 0; k < frames.size(); ++k) {
      auto frame = dhpd::io::read_frame(frames[k].string());
      if (k + 1 + which == frames.size()) change(frame.fields);
      std::vector<dhpd::io::PointField> fields;
      for (const auto& [name, field] : frame.fields) {
        dhpd::io::PointField f{name, field.first, field.second};
        if (frame.field_types.at(name) != "double")
          f.values = std::vector<std::int32_t>(field.second.begin(), field.second.end());
        fields.push_back(f);
      }
      series.write(frame.time, frame.step, frame.points, fields);
    }
    for (const auto& f : frames) fs::rename(scratch / f.filename(), f);
    fs::remove_all(scratch);
  }

  /// `path` with cell `column` of data row `row` (0 = first after the header) replaced.
  void doctor_csv(const fs::path& path, std::size_t row, std::size_t column,
                  const std::string& value) {
    auto h = read_history(path);
    h.rows.at(row).at(column) = value;
    std::string text = h.header + "\n";
    for (const auto& r : h.rows) {
      for (std::size_t k = 0; k < r.size(); ++k) text += (k ? "," : "") + r[k];
      text += "\n";
    }
    std::ofstream(path, std::ios::binary) << text;
  }

  /// The cells of stress.csv as header name → value for the first case.
  /// The cells of a CSV line, with double-quoted cells (which may hold commas and "").
  static std::vector<std::string> csv_cells(const std::string& line) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (std::size_t k = 0; k < line.size(); ++k) {
      const char c = line[k];
      if (quoted && c == '"' && k + 1 < line.size() && line[k + 1] == '"') {
        cells.back() += '"', ++k;
      } else if (c == '"') {
        quoted = !quoted;
      } else if (c == ',' && !quoted) {
        cells.emplace_back();
      } else {
        cells.back() += c;
      }
    }
    return cells;
  }
  std::map<std::string, std::string> first_case(const fs::path& out) {
    std::istringstream in(read_text(out / "stress.csv"));
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    const auto names = csv_cells(header), values = csv_cells(row);
    std::map<std::string, std::string> cells;
    for (std::size_t k = 0; k < names.size() && k < values.size(); ++k) cells[names[k]] = values[k];
    return cells;
  }
};

constexpr std::size_t kKinetic = 6, kMomentumX = 9;

/// The line of `text` that starts with `start` ("" when none).
std::string line_of(const std::string& text, const std::string& start) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(start, 0) == 0) return line;
  return "";
}

TEST_F(CliStress, SuiteOfTwoCasesPassesAndWritesTheTable) {
  write("suite.yaml", "name: mini\ncases:\n  - name: bar\n    scene: " + kStressCases +
                          "horizon_ratio_1d.yaml\n    expect: {horizon_ratio: 9.99, "
                          "broken_bonds: 1}\n  - name: plate\n    scene: " +
                          kStressCases +
                          "long_elastic.yaml\n    set: {time.steps: 2000}\n"
                          "    sweep: {time.safety: [0.5, 0.95]}\n");
  const auto o = dhpd({"stress", "suite.yaml", "-o", "st"});
  ASSERT_EQ(o.code, 0) << o.out << o.err;
  for (const char* run : {"bar", "plate-0.5", "plate-0.95"})
    for (const char* t : {"threads1", "threads2"})
      EXPECT_TRUE(fs::exists(dir_ / "st" / run / t / "history.csv")) << run << t;
  const auto cells = first_case(dir_ / "st");
  EXPECT_EQ(cells.at("case"), "bar");
  EXPECT_EQ(cells.at("pass"), "True");
  EXPECT_EQ(cells.at("reproducible"), "identical");
  EXPECT_EQ(cells.at("broken_bonds"), "90");  // the bar breaks where the two waves meet
  EXPECT_LT(std::stod(cells.at("momentum")), 1e-13);
  EXPECT_LT(std::stod(cells.at("energy")), 1e-3);
  EXPECT_GT(std::stod(cells.at("horizon_ratio")), 9.99);
  const std::string md = read_text(dir_ / "st" / "stress.md");
  EXPECT_NE(md.find("| plate-0.95 |"), std::string::npos) << md;
  EXPECT_NE(md.find("Every criterion of every case passes."), std::string::npos) << md;
}

TEST_F(CliStress, GhostForcesOfClassicalVariableFailTheMomentumCriterion) {
  write_suite("horizon_ratio_1d.yaml", "    set: {model: classical-variable}\n");
  const auto o = dhpd({"stress", "suite.yaml", "-o", "st"});
  EXPECT_EQ(o.code, 1) << o.out << o.err;
  const auto cells = first_case(dir_ / "st");
  EXPECT_EQ(cells.at("momentum_pass"), "False");
  EXPECT_GT(std::stod(cells.at("momentum")), 1e-3);  // measured 5.7e-2; DH-PD 2.1e-15
  EXPECT_EQ(cells.at("energy_pass"), "True");        // only the momentum criterion fails
  EXPECT_EQ(cells.at("reproducible"), "identical");
  EXPECT_NE(o.out.find("case: FAIL momentum"), std::string::npos) << o.out;
  EXPECT_NE(read_text(dir_ / "st" / "stress.md").find("**FAIL**"), std::string::npos);
}

TEST_F(CliStress, GhostForcesOnTheIrregularMeshFailEnergyAndMomentumOfARealRun) {
  // The 4.5x-horizon mesh with fracture: dual horizons pass, classical-variable's ghost forces
  // do work (energy rises above the budget: measured 1.17 %) and push the body (2.8e-2).
  const std::string scene = kStressCases + "irregular_2d.yaml";
  for (const std::string model : {"dual-horizon", "classical-variable"}) {
    const auto run = dhpd({"run", scene, "-o", model, "-q", "--threads", "2"},
                          {"model=" + model, "time.end=1.2e-5"});
    ASSERT_EQ(run.code, 0) << run.err;
    const auto o = check({dir_ / model});
    const bool ghost = model == "classical-variable";
    EXPECT_EQ(o.code, ghost ? 1 : 0) << o.out;
    EXPECT_EQ(line_of(o.out, "energy:").find("FAIL") != std::string::npos, ghost) << o.out;
    EXPECT_EQ(line_of(o.out, "momentum:").find("FAIL") != std::string::npos, ghost) << o.out;
    EXPECT_EQ(line_of(o.out, "volume:").find("pass") != std::string::npos, true) << o.out;
  }
}

TEST_F(CliStress, EnergyAboveTheBoundFailsAndBelowItPasses) {
  // Until time.check_dt lands (a fixed dt above the stable one is refused at load time today),
  // the history of a real run is doctored: one row's kinetic energy raised by 2 % of the scale
  // fails, by 0.5 % passes (the bound is 1 % of max(E0 + |W|); W = 0 here).
  const fs::path a = run_bar("a", 1);
  const auto h = read_history(a / "history.csv");
  const double e0 = std::stod(h.rows[0][kKinetic]) + std::stod(h.rows[0][7]);
  const std::size_t row = h.rows.size() / 2;
  const double total = std::stod(h.rows[row][kKinetic]) + std::stod(h.rows[row][7]);
  for (const double excess : {0.005, 0.02}) {
    const double kinetic = std::stod(h.rows[row][kKinetic]) + (e0 - total) + excess * e0;
    doctor_csv(a / "history.csv", row, kKinetic, fmt::format("{:.17g}", kinetic));
    const auto o = check({a});
    EXPECT_EQ(o.code, excess > 0.01 ? 1 : 0) << o.out << o.err;
    EXPECT_NE(o.out.find(excess > 0.01 ? "energy: 0.02 FAIL" : "energy: 0.005 pass"),
              std::string::npos)
        << o.out;
  }
}

TEST_F(CliStress, FixedStepOneAndAHalfTimesTheStableOneFails) {
  // `time.check_dt: false` lets a fixed dt of 1.5x the stable one `check` prints (the per-particle
  // bound (9.1)) through the loader; on the 10x bar it goes unstable and the run's guard stops it
  // (exit 3, status "unstable"; the 2D cases stay stable at 1.5x: the bound is 0.6 of their
  // limit, docs/theory.md §9; 2x blows up at once).
  // The guard stops it before a history row records the growth, so the energy criterion of the
  // rows written may still pass: the status criterion is the one that fails.
  const std::string scene = kStressCases + "horizon_ratio_1d.yaml";
  const auto probe = dhpd({"check", scene}, {"time.check_dt=false"});
  ASSERT_EQ(probe.code, 0) << probe.err;
  // The built body's stable step (check prints the estimate's interior one first).
  const auto at = probe.out.find("stable_dt: ", probe.out.find("derived:"));
  ASSERT_NE(at, std::string::npos) << probe.out;
  const double stable = std::stod(probe.out.substr(at + 11));
  write_suite("horizon_ratio_1d.yaml",
              fmt::format("    set: {{time.check_dt: false, time.dt: {:.17g}}}\n", 1.5 * stable));
  const auto o = dhpd({"stress", "suite.yaml", "-o", "st"});
  EXPECT_EQ(o.code, 1) << o.out << o.err;
  const auto cells = first_case(dir_ / "st");
  EXPECT_EQ(cells.at("pass"), "False");
  EXPECT_EQ(cells.at("status_pass"), "False") << o.out;
  EXPECT_NE(cells.at("status").find("exit [3, 3]"), std::string::npos) << cells.at("status");
  EXPECT_NE(o.out.find("1.5 x the stable step"), std::string::npos) << o.out;
}

TEST_F(CliStress, NaNInTheHistoryOrTheLastFrameFailsFiniteness) {
  const fs::path a = run_bar("a", 1);
  ASSERT_EQ(check({a}).code, 0);
  doctor_csv(a / "history.csv", 3, kMomentumX, "nan");
  const auto o = check({a});
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.out.find("finite: 1 FAIL"), std::string::npos) << o.out;
  const fs::path b = run_bar("b", 1);
  doctor_last_frame(b, [](auto& fields) { fields.at("velocity").second.at(7) = INFINITY; });
  const auto frame = check({b});
  EXPECT_EQ(frame.code, 1);
  EXPECT_NE(frame.out.find("finite: 1 FAIL"), std::string::npos) << frame.out;
  // Every frame is scanned, not only the last: a NaN damage in the fourth frame from the end.
  const fs::path c = run_bar("c", 1);
  doctor_last_frame(
      c, [](auto& fields) { fields.at("damage").second.at(3) = NAN; }, 3);
  const auto earlier = check({c});
  EXPECT_EQ(earlier.code, 1);
  EXPECT_NE(earlier.out.find("finite: 1 FAIL"), std::string::npos) << earlier.out;
}

TEST_F(CliStress, ZeroVolumeInAFrameFailsTheVolumeCriterion) {
  const fs::path a = run_bar("a", 1);
  doctor_last_frame(a, [](auto& fields) { fields.at("volume").second.at(12) = 0.0; });
  const auto o = check({a});
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(o.out.find("volume: 0 FAIL"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("energy: "), std::string::npos);
}

TEST_F(CliStress, OneAndTwoThreadsAgreeAndADoctoredSecondRunFails) {
  const fs::path one = run_bar("one", 1), two = run_bar("two", 2);
  const auto same = check({one, two});
  EXPECT_EQ(same.code, 0) << same.out;
  EXPECT_NE(same.out.find("reproducible: identical pass"), std::string::npos) << same.out;
  // The last bit of one momentum cell.
  auto h = read_history(two / "history.csv");
  const double p = std::stod(h.rows[5][kMomentumX]);
  doctor_csv(two / "history.csv", 5, kMomentumX,
             fmt::format("{:.17g}", std::nextafter(p, p > 0 ? 2 * p : 1.0)));
  const auto history = check({one, two});
  EXPECT_EQ(history.code, 1);
  EXPECT_NE(history.out.find("history.csv: row 6 column momentum_x"), std::string::npos)
      << history.out;
  // The history restored, one displacement of the last frame one ulp off.
  const fs::path three = run_bar("three", 2);
  doctor_last_frame(three, [](auto& fields) {
    double& u = fields.at("displacement").second.at(30);
    u = std::nextafter(u, 1.0);
  });
  const auto frame = check({one, three});
  EXPECT_EQ(frame.code, 1);
  EXPECT_NE(frame.out.find("last frame: array displacement differs"), std::string::npos)
      << frame.out;
}

TEST_F(CliStress, ACaseThatIsNoLongerHardOrDoesNotRunFails) {
  write_suite("horizon_ratio_1d.yaml", "    expect: {max_level: 1}\n");
  const auto easy = dhpd({"stress", "suite.yaml", "-o", "st"});
  EXPECT_EQ(easy.code, 1);
  EXPECT_NE(easy.out.find("max_level 0 < 1"), std::string::npos) << easy.out;
  write_suite("horizon_ratio_1d.yaml", "    set: {time.safety: 1.5}\n");
  const auto refused = dhpd({"stress", "suite.yaml", "-o", "st2"});
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.out.find("status exit [2, 2]"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("time.safety"), std::string::npos) << refused.out;
}

TEST_F(CliStress, BadSuiteInputIsRefusedWithFileLineAndKey) {
  write_suite("horizon_ratio_1d.yaml", "    speed: fast\n");
  const auto unknown = dhpd({"stress", "suite.yaml"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("suite.yaml:5: cases.0.speed: unknown key 'speed' (allowed: "),
            std::string::npos)
      << unknown.err;
  write_suite("nowhere.yaml");
  const auto missing = dhpd({"stress", "suite.yaml"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("suite.yaml:4: cases.0.scene: no such scene file"), std::string::npos)
      << missing.err;
  write_suite("horizon_ratio_1d.yaml", "    criteria: {momentum_axes: [y]}\n");
  const auto no_reason = dhpd({"stress", "suite.yaml"});
  EXPECT_EQ(no_reason.code, 2);
  EXPECT_NE(no_reason.err.find("cases.0.criteria: per-case criteria need a 'reason'"),
            std::string::npos)
      << no_reason.err;
  write_suite("horizon_ratio_1d.yaml",
              "    criteria: {energy_tolerance: -1}\n    reason: a test\n");
  const auto negative = dhpd({"stress", "suite.yaml"});
  EXPECT_EQ(negative.code, 2);
  EXPECT_NE(negative.err.find("cases.0.criteria.energy_tolerance: must be a number > 0, got -1"),
            std::string::npos)
      << negative.err;
  EXPECT_EQ(dhpd({"stress", "absent.yaml"}).code, 2);
  EXPECT_EQ(dhpd({"stress", "--check", "absent"}).code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "stress-mini"));
}

}  // namespace
