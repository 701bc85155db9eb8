// Runs that never lose, mix or corrupt data (issue 14) through the binary: scenes too big for the
// machine refused before anything is allocated, `check` fast and agreeing with the built body,
// runaway refinement stopped with its state, another run's folder refused, I/O errors located
// (file in the way, full disk), run.log, signals inside a refinement event, the restart hint,
// warnings, provenance and units.
#include <sys/mount.h>

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <regex>

#include "tests/support/checkpoint_cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The number after `key: ` in `text`, searching from `from`; NaN when absent.
double number_after(const std::string& text, const std::string& key, std::size_t from = 0) {
  const auto at = text.find(key + ": ", from);
  return at == std::string::npos ? NAN : std::stod(text.substr(at + key.size() + 2));
}

// A 1 m cube at 1 mm: 1e9 particles, about 1.2e11 bonds.
constexpr const char* kBillion = R"(name: big
dimension: 3
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
body:
  - {shape: box, min: [0, 0, 0], max: [1, 1, 1], spacing: 0.001, material: glass}
time: {steps: 10}
)";

class RunSafety : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    write("adaptive.yaml", kAdaptivePlate);
  }
  /// Starts `dhpd ARGS` in the test directory with stdout and stderr into files.
  pid_t spawn(const std::vector<std::string>& args, const std::string& name) {
    return spawn_dhpd(dir_, args, (dir_ / (name + ".stdout")).string(),
                      (dir_ / (name + ".stderr")).string());
  }
  /// Waits (up to `limit` s) until `file` contains `text`; whether it did.
  bool wait_for_text(const fs::path& file, const std::string& text, double limit) {
    const auto start = Clock::now();
    while (seconds_since(start) < limit) {
      if (fs::exists(file) && contains(read_text(file), text)) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
};

TEST_F(RunSafety, ABillionParticlesAreRefusedAtOnceWithTheEstimate) {
  write("big.yaml", kBillion);
  auto start = Clock::now();
  const auto r = dhpd({"run", "big.yaml", "-o", "out", "-q"});
  const double run_seconds = seconds_since(start);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "big.yaml: the scene needs about")) << r.err;
  EXPECT_TRUE(contains(r.err, "1e+09 particles")) << r.err;
  EXPECT_LT(run_seconds, 2.0);  // measured 0.04 s; it once took 60 s and died of bad_alloc
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  start = Clock::now();
  const auto c = dhpd({"check", "big.yaml"});
  EXPECT_LT(seconds_since(start), 2.0);
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(number_after(c.out, "particles"), 1e9) << c.out;
  EXPECT_NEAR(number_after(c.out, "bonds") / 1e9, 121.6, 1.0) << c.out;  // m = 3 in 3D: ~122
  EXPECT_TRUE(contains(c.out, "`dhpd run` refuses it")) << c.out;
  EXPECT_TRUE(contains(c.out, "built: no")) << c.out;
}

TEST_F(RunSafety, MaxMemoryBelowTheEstimateRefusesTheRun) {
  const auto r = dhpd({"run", "plate.yaml", "-o", "out", "-q", "--max-memory", "0.1"});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "--max-memory")) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  EXPECT_EQ(dhpd({"run", "plate.yaml", "-o", "out", "-q", "--max-memory", "500"}).code, 0);
}

TEST_F(RunSafety, CheckEstimateAgreesWithTheBuiltBody) {
  // Lattice counts are exact; the bonds never below the built ones and at most 10 % above
  // (measured: +7.7 % on the 1,400-particle ringing plate, where edges weigh most; +0.8 to +1.0 %
  // on the 16,000-particle branching plate and the Kalthoff-Winkler 2D plate).
  for (const char* name :
       {"plate_ringing", "branching_plate_uniform", "kalthoff_winkler_2d_uniform", "wave_bar"}) {
    const auto scene = std::string(DHPD_SOURCE_DIR) + "/cases/" + name + ".yaml";
    if (!fs::exists(scene)) continue;
    const auto c = dhpd({"check", scene, "--build"});
    ASSERT_EQ(c.code, 0) << name << c.err;
    const auto derived = c.out.find("derived:");
    ASSERT_NE(derived, std::string::npos) << c.out;
    const double built_bonds = number_after(c.out, "bonds", derived);
    EXPECT_EQ(number_after(c.out, "particles"), number_after(c.out, "particles", derived)) << name;
    const double ratio = number_after(c.out, "bonds") / built_bonds;
    EXPECT_GE(ratio, 1.0) << name << "\n" << c.out;
    EXPECT_LE(ratio, 1.10) << name << "\n" << c.out;
  }
}

TEST_F(RunSafety, RunawayRefinementStopsWithExitFourAndKeepsItsState) {
  const auto o = dhpd({"run", "adaptive.yaml", "-o", "run", "-q", "--max-memory", "120"},
                      {"effects.refinement.max_level=5"});
  EXPECT_EQ(o.code, 4) << o.err;
  std::smatch refused;
  ASSERT_TRUE(std::regex_search(
      o.err, refused, std::regex(R"(refinement stopped before splitting \d+ parents at step \d+)")))
      << o.err;
  EXPECT_FALSE(contains(o.err, "at step 10 ")) << "the first event fits the budget: " << o.err;
  const auto summary = read_json(dir_ / "run" / "summary.json");
  EXPECT_EQ(summary.at("status"), "resource_limit");
  expect_whole_pvd(dir_ / "run", "adaptive");
  // The kept state is the last good one, before the refused event: restarted under the same
  // budget, the run meets the same event and stops there again.
  const auto r =
      dhpd({"run", "adaptive.yaml", "-o", "run", "-q", "--max-memory", "120", "--restart", "run"},
           {"effects.refinement.max_level=5"});
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_TRUE(contains(r.err, refused.str())) << r.err;
}

TEST_F(RunSafety, AnotherRunsFolderIsRefusedAndOverwriteRemovesOnlyItsFiles) {
  const auto a = run_plate("a", {});
  ASSERT_TRUE(fs::exists(a / "plate_000003.vtu"));
  write("a/notes.txt", "mine\n");
  const auto again = dhpd({"run", "plate.yaml", "-o", "a", "-q"}, {"time.steps=20"});
  EXPECT_EQ(again.code, 2);
  EXPECT_TRUE(contains(again.err, "holds the outputs of another run")) << again.err;
  EXPECT_TRUE(contains(again.err, "--overwrite")) << again.err;
  EXPECT_TRUE(fs::exists(a / "plate_000003.vtu"));
  run_plate("a", {"--overwrite"}, {"time.steps=20"});
  EXPECT_EQ(read_text(a / "notes.txt"), "mine\n");
  EXPECT_TRUE(fs::exists(a / "plate_000001.vtu"));
  EXPECT_FALSE(fs::exists(a / "plate_000002.vtu"));  // the old run's later frames are gone
  EXPECT_FALSE(fs::exists(a / "plate_000003.vtu"));
  EXPECT_EQ(read_json(a / "summary.json").at("steps"), 20);
}

TEST_F(RunSafety, AFileInTheWayOfTheOutputFolderExitsFiveWithTheReason) {
  write("blocked", "a file\n");
  const auto o = dhpd({"run", "plate.yaml", "-o", "blocked/run", "-q"});
  EXPECT_EQ(o.code, 5) << o.err;
  EXPECT_TRUE(contains(o.err, "blocked")) << o.err;
  EXPECT_TRUE(contains(o.err, "Not a directory")) << o.err;
  EXPECT_FALSE(contains(o.err, "internal error")) << o.err;
}

/// After a full disk: exit 5 with the system's reason, every frame listed is whole, no temporary
/// file left, summary.json says io_error.
void expect_io_error_folder(const Outcome& o, const fs::path& dir, const char* reason) {
  EXPECT_EQ(o.code, 5) << o.err;
  EXPECT_TRUE(contains(o.err, reason)) << o.err;
  EXPECT_FALSE(contains(o.err, "internal error")) << o.err;
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_FALSE(contains(entry.path().filename().string(), ".tmp")) << entry.path();
  if (fs::exists(dir / "adaptive.pvd")) expect_whole_pvd(dir, "adaptive");
  ASSERT_TRUE(fs::exists(dir / "summary.json"));
  const auto summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary.at("status"), "io_error");
  EXPECT_TRUE(contains(summary.at("message").get<std::string>(), reason));
}

TEST_F(RunSafety, AFileSizeLimitStopsTheRunWithWholeFiles) {
  // RLIMIT_FSIZE (with SIGXFSZ ignored) fails writes past 256 KB with EFBIG: history.csv and
  // the frames grow past it while summary.json still fits.
  const auto o = dhpd(
      {"-c", "ulimit -f 256; trap '' XFSZ; exec \"$0\" run adaptive.yaml -o full -q", DHPD_BIN}, {},
      "/bin/sh");
  expect_io_error_folder(o, dir_ / "full", "File too large");
}

TEST_F(RunSafety, AFullTmpfsStopsTheRunWithWholeFramesAndASummary) {
  const auto mount_point = dir_ / "small";
  fs::create_directories(mount_point);
  if (mount("tmpfs", mount_point.c_str(), "tmpfs", 0, "size=1m") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno) << ")";
  const auto o = dhpd({"run", "adaptive.yaml", "-o", "small/run", "-q"});
  const auto copy = dir_ / "copy";
  fs::copy(mount_point / "run", copy);  // read before the unmount
  umount(mount_point.c_str());
  expect_io_error_folder(o, copy, "No space left on device");
}

TEST_F(RunSafety, RunLogHasTimestampedLinesAndStdoutIsNotHeldBack) {
  const pid_t pid = spawn({"run", "adaptive.yaml", "-o", "run"}, "run");
  // Line-buffered stdout: the start of the run shows while it runs, not when it exits.
  EXPECT_TRUE(wait_for_text(dir_ / "run.stdout", "active effects", 20.0));
  kill(pid, SIGKILL);
  EXPECT_EQ(wait_for(pid), 128 + SIGKILL);
  const auto log = read_text(dir_ / "run" / "run.log");
  const std::regex stamped(R"(^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d{3} UTC  dhpd: )");
  std::istringstream lines(log);
  int count = 0;
  for (std::string line; std::getline(lines, line); ++count)
    EXPECT_TRUE(std::regex_search(line, stamped)) << line;
  EXPECT_GE(count, 2) << log;
  EXPECT_TRUE(contains(log, "active effects")) << log;
}

TEST_F(RunSafety, SigtermInsideALongRefinementEventIsHonouredWithinASecond) {
  // max_level 5 on the adaptive plate: the fourth event splits 22,356 parents (seconds).
  const pid_t pid = spawn({"run", "adaptive.yaml", "-o", "run", "--set",
                           "effects.refinement.max_level=5", "--set", "output.checkpoint_every=0"},
                          "run");
  ASSERT_TRUE(wait_for_text(dir_ / "run" / "run.log", "refinement 3 at step", 120.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // inside event 4
  const auto sent = Clock::now();
  kill(pid, SIGTERM);
  EXPECT_EQ(wait_for(pid), 143);
  const double latency = seconds_since(sent);
  EXPECT_LT(latency, 1.0);
  const auto summary = read_json(dir_ / "run" / "summary.json");
  EXPECT_EQ(summary.at("status"), "interrupted");
  const auto message = summary.at("message").get<std::string>();
  EXPECT_TRUE(contains(message, "during the refinement event")) << message;
  EXPECT_TRUE(fs::exists(dir_ / "run" / "checkpoint.bin"));
  expect_whole_pvd(dir_ / "run", "adaptive");
}

TEST_F(RunSafety, TheRestartHintRunsAsPrinted) {
  const pid_t pid = spawn({"run", "adaptive.yaml", "-o", "run", "--set", "measure.every=5", "--set",
                           "output.checkpoint_every=0"},
                          "run");
  ASSERT_TRUE(wait_for_text(dir_ / "run" / "run.log", "refinement 1 at step", 60.0));
  kill(pid, SIGINT);
  EXPECT_EQ(wait_for(pid), 130);
  const auto err = read_text(dir_ / "run.stderr");
  const auto at = err.find("continue with: ");
  ASSERT_NE(at, std::string::npos) << err;
  std::string command = err.substr(at + 15);
  command = command.substr(0, command.find('\n'));
  EXPECT_TRUE(contains(command, "--set measure.every=5")) << command;
  EXPECT_TRUE(contains(command, "--restart run")) << command;
  EXPECT_FALSE(contains(command, "DIR")) << command;
  ASSERT_EQ(command.rfind("dhpd ", 0), 0u) << command;
  const int status = std::system(
      ("cd " + quoted(dir_.string()) + " && " + quoted(DHPD_BIN) + command.substr(4) + " -q")
          .c_str());
  EXPECT_EQ(WEXITSTATUS(status), 0) << command;
  EXPECT_EQ(read_json(dir_ / "run" / "summary.json").at("status"), "completed");
}

TEST_F(RunSafety, LegalNonsenseGetsWarnings) {
  const auto o = dhpd({"run", "plate.yaml", "-o", "a", "-q", "--threads", "64"},
                      {"cracks=[[[0.02, 0.02], [0.03, 0.02]]]"});
  ASSERT_EQ(o.code, 0) << o.err;
  const auto warnings = read_json(dir_ / "a" / "summary.json").at("warnings");
  std::string all;
  for (const auto& w : warnings) all += w.get<std::string>() + "\n";
  EXPECT_TRUE(contains(all, "cuts no bond")) << all;
  EXPECT_TRUE(contains(all, "--threads 64")) << all;
  EXPECT_TRUE(contains(read_text(dir_ / "a" / "run.log"), "warning: ")) << all;
  const auto c = dhpd({"check", "plate.yaml"}, {"time.end=1000"});
  EXPECT_EQ(c.code, 0) << c.err;
  EXPECT_TRUE(contains(c.out, "warning: ")) << c.out;
  EXPECT_TRUE(contains(c.out, "steps")) << c.out;
}

TEST_F(RunSafety, UnclearInputGetsMessagesThatNameTheProblem) {
  write("tab.yaml", std::string(kPlate).replace(std::string(kPlate).find("  glass"), 2, "\t"));
  const auto tab = dhpd({"check", "tab.yaml"});
  EXPECT_EQ(tab.code, 2);
  EXPECT_TRUE(contains(tab.err, "tab")) << tab.err;
  fs::create_directories(dir_ / "folder.yaml");
  const auto folder = dhpd({"check", "folder.yaml"});
  EXPECT_EQ(folder.code, 2);
  EXPECT_TRUE(contains(folder.err, "folder.yaml: is a folder, not a scene file")) << folder.err;
  const auto list = dhpd({"check", "plate.yaml"}, {"boundary_conditions.1.velocity=[0, 5]"});
  EXPECT_EQ(list.code, 2);
  EXPECT_TRUE(contains(list.err, "x, y")) << list.err;
}

TEST_F(RunSafety, OutputsCarryProvenanceAndUnits) {
  const auto v = dhpd({"--version"});
  EXPECT_EQ(v.code, 0);
  EXPECT_TRUE(std::regex_search(v.out, std::regex(R"(^dhpd \S+)"))) << v.out;
  const auto dir = run_plate("a", {"--threads", "2"});
  const auto s = read_json(dir / "summary.json");
  EXPECT_EQ(s.at("command_line"), "dhpd run plate.yaml -o a -q --threads 2");
  EXPECT_EQ(s.at("threads"), 2);
  EXPECT_FALSE(s.at("version").get<std::string>().empty());
  EXPECT_TRUE(s.contains("commit"));
  EXPECT_GT(s.at("peak_memory_mb").get<double>(), 1.0);
  EXPECT_TRUE(contains(v.out, s.at("version").get<std::string>())) << v.out;
  // Every column of history.csv has its unit in units.json.
  const auto units = read_json(dir / "units.json");
  std::istringstream header(
      read_text(dir / "history.csv").substr(0, read_text(dir / "history.csv").find('\n')));
  for (std::string column; std::getline(header, column, ',');)
    EXPECT_TRUE(units.at("history.csv").contains(column)) << column << "\n" << units.dump(1);
  EXPECT_EQ(units.at("history.csv").at("time"), "s");
}

TEST_F(RunSafety, CheckpointsComeByWallTimeByDefault) {
  const auto dir = run_plate("a", {});
  EXPECT_TRUE(contains(read_text(dir / "scene.resolved.yaml"), "checkpoint_minutes: 1e+01"));
  // Every 60 µs of wall time: a checkpoint after most steps of the 60-step plate.
  const auto o = dhpd({"run", "plate.yaml", "-o", "b", "-q"}, {"output.checkpoint_minutes=1e-6"});
  ASSERT_EQ(o.code, 0) << o.err;
  const auto log = read_text(dir_ / "b" / "run.log");
  std::size_t count = 0;
  for (auto at = log.find("checkpoint after step"); at != std::string::npos;
       at = log.find("checkpoint after step", at + 1))
    ++count;
  EXPECT_GE(count, 3u) << log;
}

}  // namespace
