// End-to-end: `dhpd study` on the 1D bar with a spacing jump (fast), its outputs, its Pareto
// front and budget, and its refusals.
#include <sstream>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class CliStudy : public CliTest {
 protected:
  /// A study of wave_bar_1d.yaml: the reference at a quarter of the case's spacings, variants at
  /// the case's spacings and at half of them (a grid over the two parts' spacings).
  void write_study(const std::string& extra = "") {
    write("bar.yaml", "name: bar\ncase: " + std::string(DHPD_SOURCE_DIR) +
                          "/cases/wave_bar_1d.yaml\n"
                          "reference: {label: quarter, set: {body.0.spacing: 0.0104166666666666667,"
                          " body.1.spacing: 0.00104166666666666667}}\n"
                          "variants:\n"
                          "  - {label: case spacing}\n"
                          "  - {label: half, set: {body.0.spacing: 0.0208333333333333333,"
                          " body.1.spacing: 0.00208333333333333333}}\n"
                          "error: l2_displacement\n"
                          "budget: {l2_displacement: 0.8}\n" +
                          extra);
  }

  /// study.csv as rows of cells (header first).
  std::vector<std::vector<std::string>> table(const fs::path& csv) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(read_text(csv));
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> cells;
      std::istringstream row(
          line.substr(0, line.find(",\"{") == std::string::npos ? line.size() : line.find(",\"{")));
      for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
      rows.push_back(cells);
    }
    return rows;
  }
};

TEST_F(CliStudy, RunsVariantsAndWritesTableReportAndPareto) {
  write_study();
  const auto o = dhpd({"study", "bar.yaml", "-o", "study"});
  ASSERT_EQ(o.code, 0) << o.err;
  for (const char* f : {"study.csv", "study.md", "pareto.png"})
    EXPECT_TRUE(fs::exists(dir_ / "study" / f)) << f;
  const auto rows = table(dir_ / "study" / "study.csv");
  ASSERT_EQ(rows.size(), 4u);  // header, reference, two variants
  EXPECT_EQ(rows[0][0], "label");
  const std::size_t l2 = 10;  // label,case,wall_s,particle_steps,peak_mib,particles_end,5 metrics
  ASSERT_EQ(rows[0][l2], "l2_displacement");
  const double coarse = std::stod(rows[2][l2]), half = std::stod(rows[3][l2]);
  // The displacement error against the fine reference falls with refinement (measured 0.99 and
  // 0.71: the eq. 31 pulse is barely resolved in the coarse parts); only "half" is within 0.8.
  EXPECT_GT(coarse, 0.0);
  EXPECT_LT(half, coarse);
  EXPECT_GT(std::stod(rows[1][4]), 1.0);  // the reference's own peak memory, MiB
  const std::string md = read_text(dir_ / "study" / "study.md");
  EXPECT_NE(md.find("| case spacing |"), std::string::npos) << md;
  EXPECT_NE(md.find("Cheapest within the budget (l2_displacement ≤ 0.8): **half**"),
            std::string::npos)
      << md;
}

TEST_F(CliStudy, RefusesAMissingFileAndABadKey) {
  const auto missing = dhpd({"study", "nowhere.yaml"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nowhere.yaml: no such study file"), std::string::npos) << missing.err;
  write_study("speed: fast\n");
  const auto bad = dhpd({"study", "bar.yaml", "-o", "study"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("unknown key(s) ['speed']"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "study" / "study.csv"));
}

TEST_F(CliStudy, MirrorTipsGiveTheReferencesOwnTipPathSpread) {
  // Kalthoff–Winkler 2D, coarse, to 35 µs (the cracks start at 28 µs): the lattice, the notches and
  // the load are mirror images about y = 0, so the two cracks must be (the run is exactly
  // symmetric); the same tip against its own mirror image is 2 × its distance from y = 0 away.
  const std::string kw = std::string(DHPD_SOURCE_DIR) + "/cases/kalthoff_winkler_2d_uniform.yaml";
  const auto study = [&](const std::string& name, const std::string& mirror) {
    write(name + ".yaml", "name: " + name + "\ncase: " + kw +
                              "\nreference: {label: reference, set: {time.end: 3.5e-5}}\n"
                              "variants:\n  - {label: same, set: {time.end: 3.5e-5}}\n"
                              "frames: 1\nmirror: " +
                              mirror + "\n");
    return dhpd({"study", name + ".yaml", "-o", name});
  };
  const auto spread_in = [&](const std::string& name) {
    const std::string md = read_text(dir_ / name / "study.md");
    const auto at = md.find("Reference's own tip-path spread");
    EXPECT_NE(at, std::string::npos) << md;
    const auto colon = md.find("): ", at);
    return std::stod(md.substr(colon + 3));
  };
  ASSERT_EQ(study("pair", "{tips: [upper, lower], axis: 1}").code, 0);
  EXPECT_LT(spread_in("pair"), 1e-9);
  ASSERT_EQ(study("self", "{tips: [upper, upper], axis: 1}").code, 0);
  EXPECT_GT(spread_in("self"), 2 * 0.025);  // the upper crack lies above y = 25 mm
  const auto bad = study("bad", "{tips: [upper], axis: 4}");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("mirror must be {tips: [TIP, TIP], axis: 0|1|2, at: NUMBER}"),
            std::string::npos)
      << bad.err;
}

TEST_F(CliStudy, AnglesGiveEachRunsEarlyAndFinalCrackAngles) {
  // Kalthoff–Winkler 2D, coarse, to 50 µs: both cracks run past 20 mm. angles.csv holds, per run
  // and tip, the final chord angle of summary.json and the early angle (median chord angle while
  // the tip lay 10 to 20 mm from the notch tip), which must be one of cracks.csv's angles then.
  const std::string kw = std::string(DHPD_SOURCE_DIR) + "/cases/kalthoff_winkler_2d_uniform.yaml";
  const auto study = [&](const std::string& angles) {
    write("kw.yaml", "name: kw\ncase: " + kw +
                         "\nreference: {label: reference, set: {time.end: 5.0e-5}}\n"
                         "variants:\n  - {label: same, set: {time.end: 5.0e-5}}\n"
                         "frames: 1\nangles: " +
                         angles + "\n");
    return dhpd({"study", "kw.yaml", "-o", "kw"});
  };
  ASSERT_EQ(study("{early_distance: 0.02}").code, 0);
  const auto rows = table(dir_ / "kw" / "angles.csv");
  ASSERT_EQ(rows.size(), 5u);  // header, two runs × two tips
  EXPECT_EQ(rows[0], (std::vector<std::string>{"label", "tip", "initiation_time", "early_angle_deg",
                                               "angle_deg", "distance", "published_angle_deg"}));
  const auto summary = read_json(dir_ / "kw" / "run-00" / "summary.json");
  const auto cracks = read_history(dir_ / "kw" / "run-00" / "cracks.csv");
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& row = rows[3 + k];
    EXPECT_EQ(row[0], "same");
    EXPECT_NEAR(std::stod(row[4]), summary.at("cracks")[k].at("angle_deg").get<double>(), 1e-9);
    EXPECT_EQ(row[6], "65.7");
    const double early = std::stod(row[3]);
    std::size_t in_band = 0, matches = 0;
    for (const auto& c : cracks.rows) {
      const double d = std::stod(c.at(6));
      if (c.at(2) != row[1] || d < 0.01 || d > 0.02) continue;
      ++in_band;
      matches += std::abs(std::stod(c.at(9)) - early) < 1e-9;
    }
    EXPECT_GT(in_band, 0u);
    EXPECT_GT(matches, 0u) << "early angle " << early << " is no angle of the 10-20 mm band";
  }
  EXPECT_NE(read_text(dir_ / "kw" / "study.md").find("| same | lower |"), std::string::npos);
  const auto bad = study("{early_distance: -1}");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("angles must be {early_distance: NUMBER > 0} (m)"), std::string::npos)
      << bad.err;
}

}  // namespace
