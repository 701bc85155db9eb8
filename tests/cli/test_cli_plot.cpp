// End-to-end: `dhpd plot` and `dhpd report` on short runs of the binary and on a hand-written
// run directory with crack measurements and published numbers.
#include <fmt/format.h>

#include <cstdlib>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class CliPlot : public CliTest {
 protected:
  /// The test plate's run (60 steps, frames at steps 0, 20, 40, 60) in `out`.
  fs::path run(const std::string& out = "result") { return run_plate(out, {}); }

  /// A run directory with summary.json (`extra` added to its top-level map), history.csv and
  /// cracks.csv written by hand, and no frames.
  fs::path fake_crack_run(const std::string& extra) {
    const fs::path dir = dir_ / "fake";
    fs::create_directories(dir);
    write("fake/summary.json", R"({"scene": "branching", "status": "completed", "message": "",
      "wall_seconds": 12.5, "steps": 400, "end_time": 4.6e-5, "dt": 1.15e-7,
      "critical_dt": 1.4e-7, "particles_start": 54000, "particles_end": 54000,
      "bonds": 1000000, "broken_bonds": 5000, "refinement_events": 0, "rayleigh_speed": 2119.0,
      "cracks": [{"name": "lower", "initiation_time": 2.7e-5, "angle_deg": 66.0,
                  "max_speed": 1500.0, "mean_speed": 1200.0, "branch_times": [2.5e-5, 3.0e-5],
                  "branch_positions": [[0.06, 0.02, 0.0], [0.07, 0.01, 0.0]],
                  "tip": [0.09, 0.03, 0.0]}])" +
                                   extra + "}\n");
    std::string history = std::string(kHistoryHeader) + "\n";
    for (int k = 0; k <= 4; ++k)
      history += fmt::format("{},{},1.15e-7,54000,1000000,{},{},{},{},{},1e-18,0\n", 100 * k,
                             1.15e-5 * k, 1000 * k, 0.01 * k, 0.02 * k, 0.035 * k, 1e-17 * k);
    write("fake/history.csv", history);
    std::string cracks = "step,time,tip,x,y,z,distance,path_length,speed,angle_deg,branches\n";
    for (int k = 0; k < 5; ++k) {
      const double t = 2.7e-5 + 4e-6 * k, s = 1.5e-3 * k;
      cracks += fmt::format("{},{},0,{},{},0,{},{},{},66,0\n", 230 + 30 * k, t, 0.05 + s,
                            0.02 - 0.5 * s, s, s, 300.0 * k);
      cracks += fmt::format("{},{},1,{},{},0,{},{},{},-64,0\n", 230 + 30 * k, t, 0.05 + s,
                            0.02 + 0.5 * s, s, s, 280.0 * k);
    }
    write("fake/cracks.csv", cracks);
    return dir;
  }
};

const std::vector<std::string> kRunPictures{"damage_0.png",    "damage_1.png", "damage_2.png",
                                            "damage_3.png",    "energies.png", "momentum.png",
                                            "particles_dt.png"};
const std::vector<std::string> kCrackPictures{"tip_speed.png", "crack_path.png"};

/// A real picture: the PNG signature and more than 5 kB (an empty figure is smaller).
void expect_png(const fs::path& path) {
  ASSERT_TRUE(fs::is_regular_file(path)) << path;
  const std::string bytes = read_text(path);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  EXPECT_GT(bytes.size(), 5000u) << path;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST_F(CliPlot, PlotWritesEveryPictureOfARun) {
  const auto dir = run();
  const auto o = dhpd({"plot", "result"});
  ASSERT_EQ(o.code, 0) << o.err;
  for (const auto& png : kRunPictures) expect_png(dir / "plots" / png);
  for (const auto& png : kCrackPictures) EXPECT_FALSE(fs::exists(dir / "plots" / png)) << png;
  EXPECT_FALSE(fs::exists(dir / "plots" / "damage_4.png"));
  EXPECT_TRUE(contains(o.out, "note: no cracks.csv in result")) << o.out;
  // The four frames spread over the collection are all of them, in order.
  EXPECT_TRUE(contains(o.out, "damage_0.png: plate_000000.vtu, t = 0 µs")) << o.out;
  EXPECT_TRUE(contains(o.out, "damage_3.png: plate_000003.vtu")) << o.out;
}

TEST_F(CliPlot, TimesPickTheNearestFramesAndFieldSelectsTheField) {
  const auto dir = run();
  ASSERT_EQ(dhpd({"plot", "result"}).code, 0);
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  ASSERT_EQ(pvd.size(), 4u);
  const std::string times = fmt::format("{:.17g},{:.17g}", 1.1 * pvd[2].first, pvd[1].first);
  const auto o = dhpd({"plot", "result", "--times", times});
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_TRUE(contains(o.out, "damage_0.png: plate_000002.vtu")) << o.out;
  EXPECT_TRUE(contains(o.out, "damage_1.png: plate_000001.vtu")) << o.out;
  expect_png(dir / "plots" / "damage_1.png");
  EXPECT_FALSE(fs::exists(dir / "plots" / "damage_2.png"));  // the earlier plot's are gone
  const auto v = dhpd({"plot", "result", "--field", "velocity", "--times", times});
  ASSERT_EQ(v.code, 0) << v.err;
  expect_png(dir / "plots" / "velocity_0.png");
  expect_png(dir / "plots" / "damage_0.png");  // other fields' pictures stay
  const auto bad = dhpd({"plot", "result", "--field", "pressure"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "no point field 'pressure' (fields: displacement")) << bad.err;
}

TEST_F(CliPlot, ReportMakesThePlotsAndLinksThem) {
  const auto dir = run();
  const auto o = dhpd({"report", "result"});
  ASSERT_EQ(o.code, 0) << o.err;
  const std::string report = read_text(dir / "report.md");
  for (const auto& png : kRunPictures) {
    expect_png(dir / "plots" / png);
    EXPECT_TRUE(contains(report, "](plots/" + png + ")")) << png << "\n" << report;
  }
  EXPECT_TRUE(contains(report, "# plate: run report")) << report;
  EXPECT_TRUE(contains(report, "| status | completed |")) << report;
  EXPECT_TRUE(contains(report, "| particles | 200 → 200 |")) << report;
  EXPECT_TRUE(contains(report, "| steps | 60 |")) << report;
  EXPECT_TRUE(contains(report, "no crack measurements")) << report;
}

TEST_F(CliPlot, ReportQuotesTheSceneFilesHeader) {
  // The header comment (source, what the case shows, what to expect) opens the report; a scene
  // without one (the plate above) gets no such section.
  write("headed.yaml", std::string("# A plate to test the report.\n#\n# It expects 60 steps.\n") +
                           kPlate + "# not part of the header\n");
  const auto o = dhpd({"run", "headed.yaml", "-o", "headed", "-q"});
  ASSERT_EQ(o.code, 0) << o.err;
  ASSERT_EQ(dhpd({"report", "headed"}).code, 0);
  const std::string report = read_text(dir_ / "headed" / "report.md");
  EXPECT_TRUE(contains(report,
                       "## About this case (the scene file's header)\n\n"
                       "> A plate to test the report.\n>\n> It expects 60 steps.\n\n"))
      << report;
  EXPECT_FALSE(contains(report, "not part of the header")) << report;
  run("plain");
  ASSERT_EQ(dhpd({"report", "plain"}).code, 0);
  EXPECT_FALSE(contains(read_text(dir_ / "plain" / "report.md"), "About this case"));
}

TEST_F(CliPlot, ThreeDFramesShowTheMidThicknessSlice) {
  write("block.yaml", R"(name: block
dimension: 3
materials:
  g: {E: 1.0e9, rho: 1000}
body:
  - {shape: box, min: [0, 0, 0], max: [0.004, 0.004, 0.0025], spacing: 0.0005, material: g}
effects: {fracture: false}
time: {steps: 10}
output: {every: 5}
)");
  ASSERT_EQ(dhpd({"run", "block.yaml", "-o", "block", "-q"}).code, 0);
  const auto o = dhpd({"plot", "block"});
  ASSERT_EQ(o.code, 0) << o.err;
  // 8 x 8 x 5 particles; the middle layer of 64 lies on z = 1.25 mm.
  EXPECT_TRUE(contains(o.out, "mid-thickness slice z ≈ 1.25 mm (64 of 320 particles)")) << o.out;
  expect_png(dir_ / "block" / "plots" / "damage_2.png");
}

TEST_F(CliPlot, CrackRunGetsTipPicturesAndTheMeasuredVersusPublishedTable) {
  const auto dir = fake_crack_run(R"(, "published": {"lower": {"angle_deg": 65.7,
      "initiation_time": 2.6e-5, "branch_times": [2.45e-5]}, "particles_end": 54860})");
  const auto o = dhpd({"report", "fake"});
  ASSERT_EQ(o.code, 0) << o.err;
  for (const auto& png : kCrackPictures) expect_png(dir / "plots" / png);
  EXPECT_TRUE(contains(o.out, "note: no frames")) << o.out;
  const std::string report = read_text(dir / "report.md");
  for (const auto& png : kCrackPictures)
    EXPECT_TRUE(contains(report, "](plots/" + png + ")")) << png << "\n" << report;
  // (66.0 − 65.7) / 65.7, (2.7 − 2.6) / 2.6, the first branch (2.5 − 2.45) / 2.45, and a
  // top-level key against summary's own value: (54000 − 54860) / 54860. The measured numbers
  // without a published value (speeds, branchings, the tip) stay in the table.
  for (const char* row :
       {"| quantity | measured | published | difference |",
        "| angle at the end (°) | 66 | 65.7 | +0.46 % |",
        "| initiation time (µs) | 27 | 26 | +3.85 % |",
        "| first branching (µs) | 25 | 24.5 | +2.04 % |",
        "| max speed (m/s) | 1500 (0.71 c_R) | — | — |",
        "| tip at the end (mm) | (90, 30, 0) | — | — |",
        "| particles_end | 54000 | 54860 | -1.57 % |", "| threads | not recorded |"})
    EXPECT_TRUE(contains(report, row)) << row << "\n" << report;
}

TEST_F(CliPlot, ReportWithoutPublishedListsTheMeasuredCracks) {
  const auto dir = fake_crack_run("");
  ASSERT_EQ(dhpd({"report", "fake"}).code, 0);
  const std::string report = read_text(dir / "report.md");
  EXPECT_FALSE(contains(report, "| difference |")) << report;
  for (const char* row :
       {"| quantity | measured |", "| angle at the end (°) | 66 |",
        "| max speed (m/s) | 1500 (0.71 c_R) |", "| branchings | 2 |",
        "| tip at the end (mm) | (90, 30, 0) |", "Rayleigh speed c_R = 2119 m/s."})
    EXPECT_TRUE(contains(report, row)) << row << "\n" << report;
}

TEST_F(CliPlot, MissingDirectoryIsRefused) {
  for (const char* command : {"plot", "report"}) {
    const auto o = dhpd({command, "nowhere"});
    EXPECT_EQ(o.code, 2) << command;
    EXPECT_TRUE(contains(o.err,
                         "dhpd: error: nowhere: no such directory; expected the output "
                         "directory of a dhpd run, with history.csv or frames"))
        << o.err;
  }
}

TEST_F(CliPlot, DirectoryWithNothingToPlotIsRefused) {
  fs::create_directories(dir_ / "partial");
  write("partial/history.csv", std::string(kHistoryHeader) + "\n");
  const auto o = dhpd({"report", "partial"});
  EXPECT_EQ(o.code, 2);
  EXPECT_TRUE(contains(o.err,
                       "dhpd: error: partial/history.csv: no rows, and no frames; expected "
                       "the output directory of a dhpd run"))
      << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "partial" / "report.md"));
  fs::remove(dir_ / "partial" / "history.csv");
  write("partial/summary.json", "{}\n");
  const auto p = dhpd({"plot", "partial"});
  EXPECT_EQ(p.code, 2);
  EXPECT_TRUE(contains(p.err, "partial: neither history.csv nor a frame (.vtu);")) << p.err;
}

TEST_F(CliPlot, MissingMatplotlibNamesTheDebianPackage) {
  // A matplotlib that fails to import, found first on PYTHONPATH, stands for one not installed.
  fs::create_directories(dir_ / "python" / "matplotlib");
  write("python/matplotlib/__init__.py", "raise ImportError('No module named matplotlib')\n");
  fake_crack_run("");
  ASSERT_EQ(setenv("PYTHONPATH", (dir_ / "python").c_str(), 1), 0);
  const auto o = dhpd({"plot", "fake"});
  unsetenv("PYTHONPATH");
  EXPECT_EQ(o.code, 2);
  EXPECT_TRUE(contains(o.err, "the Python module 'matplotlib' is missing")) << o.err;
  EXPECT_TRUE(contains(o.err, "sudo apt-get install python3-matplotlib")) << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "fake" / "plots"));
}

}  // namespace
