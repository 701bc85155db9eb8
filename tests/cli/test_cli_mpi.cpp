// Distributed runs through mpirun (docs/theory.md §25): any rank count writes the serial run's
// outputs byte for byte, restarts cross rank counts, and bad input is reported once, by rank 0.
#include <fmt/core.h>

#include <cstdlib>

#include "tests/support/checkpoint_cli.hpp"

namespace dhpd::cli_test {
namespace {

class MpiCli : public CliTest {
 protected:
  /// `mpirun -np RANKS dhpd ARGS... --set S...` (one OpenMP thread per rank).
  Outcome mpi(int ranks, std::vector<std::string> args, const std::vector<std::string>& sets = {}) {
    // CI machines run as root; OpenMPI refuses that unless told.
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    std::vector<std::string> all{"--oversubscribe",   "-np",   std::to_string(ranks), "-x",
                                 "OMP_NUM_THREADS=1", DHPD_BIN};
    all.insert(all.end(), args.begin(), args.end());
    return dhpd(all, sets, DHPD_MPIEXEC);
  }
  /// Occurrences of `word` in `text`.
  static int count(const std::string& text, const std::string& word) {
    int n = 0;
    for (auto at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
  }
};

TEST_F(MpiCli, OneToFourRanksWriteTheSerialRunsOutputsByteForByte) {
  // The pre-cracked plate with fracture: bonds break on every rank's share of the rows.
  const auto ref = run_plate("ref", {}, {"time.steps=200"});
  ASSERT_GT(read_history(ref / "history.csv").column(5).back(), 20) << "bonds break";
  for (const int ranks : {1, 2, 3, 4}) {
    const std::string out = "np" + std::to_string(ranks);
    const auto o = mpi(ranks, {"run", "plate.yaml", "-o", out, "-q"}, {"time.steps=200"});
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_EQ(o.out, "");
    expect_same_outputs(ref, dir_ / out, "plate");
    EXPECT_EQ(read_json(dir_ / out / "summary.json").at("ranks"), ranks);
  }
}

TEST_F(MpiCli, ShippedCasesOfEveryFamilyAndSolverGiveTheSerialBits) {
  // The elastic 2D wave through a fine/coarse interface (dual horizons, interface factors), the
  // 3D Kalthoff–Winkler plate at 3.125 mm (4,096 particles; 2,488 bonds break by 40 µs), and its
  // fine/coarse variant with multi-rate stepping (three time levels, 4,348 bonds break), and the
  // ordinary state-based adaptive Kalthoff–Winkler plate to 30 µs (12 events, 1,116 bonds break:
  // each rank's dilatations are shared before its forces), and the quasi-static notched plate in
  // 8 load steps (85 refinement events between relaxations, 3,602 bonds break), the cut-out plate
  // in tension held by fictitious layers (statics), and the vibrating plate with the
  // correspondence family (its F and σK⁻¹ shared between its two passes).
  struct Case {
    std::string file, name;
    std::vector<std::string> sets;
    int ranks;
  };
  const std::vector<Case> cases{
      {"wave_plate_2d.yaml", "wave_plate_2d", {"time.end=0.03"}, 3},
      {"kalthoff_winkler_3d_uniform.yaml",
       "kalthoff_winkler_3d_uniform",
       {"body.0.spacing=0.003125", "time.end=4e-5"},
       2},
      {"kalthoff_winkler_3d_fine_coarse.yaml",
       "kalthoff_winkler_3d_fine_coarse",
       {"body.0.spacing=0.003125", "body.1.spacing=0.0015625", "time.end=4e-5",
        "time.multirate=true"},
       4},
      {"kalthoff_winkler_2d_state_adaptive.yaml",
       "kalthoff_winkler_2d_state_adaptive",
       {"time.end=3e-5"},
       2},
      {"notched_plate_quasistatic.yaml", "notched_plate_quasistatic", {"time.steps=8"}, 2},
      {"cutout_plate_tension.yaml", "cutout_plate_tension", {}, 2},
      {"plate_vibration.yaml",
       "plate_vibration",
       {"model.family=correspondence", "horizon.factor=2"},
       3}};
  for (const auto& c : cases) {
    const std::string scene = std::string(DHPD_SOURCE_DIR) + "/cases/" + c.file;
    const auto serial = dhpd({"run", scene, "-o", c.name + "_serial", "-q"}, c.sets);
    ASSERT_EQ(serial.code, 0) << serial.err;
    const auto o = mpi(c.ranks, {"run", scene, "-o", c.name + "_mpi", "-q"}, c.sets);
    ASSERT_EQ(o.code, 0) << o.err;
    expect_same_outputs(dir_ / (c.name + "_serial"), dir_ / (c.name + "_mpi"), c.name);
    if (c.name.find("fine_coarse") != std::string::npos) {
      const auto levels = read_json(dir_ / (c.name + "_mpi") / "summary.json").at("time_levels");
      EXPECT_GE(levels.at("particles").size(), 2u) << "time levels";
    }
  }
}

TEST_F(MpiCli, AdaptiveRunWithARepartitionAfterEveryEventGivesTheSerialBits) {
  // Kalthoff–Winkler 2D adaptive to 40 µs: 17 refinement events. Every rank runs each event on
  // its copy; Zoltan cuts again after each one (events), only past 10 % imbalance (the default),
  // or before every step (steps: a row that changes owner must take its bond states along).
  const std::string scene =
      std::string(DHPD_SOURCE_DIR) + "/cases/kalthoff_winkler_2d_adaptive.yaml";
  const std::vector<std::string> sets{"time.end=4e-5"};  // time levels as the defaults choose them
  const auto serial = dhpd({"run", scene, "-o", "serial", "-q"}, sets);
  ASSERT_EQ(serial.code, 0) << serial.err;
  const auto events = read_text(dir_ / "serial" / "refinement.csv");
  ASSERT_GT(std::count(events.begin(), events.end(), '\n'), 10) << "refinement events";
  for (const auto& [ranks, policy] : std::vector<std::pair<int, std::string>>{
           {2, "events"}, {3, "events"}, {4, "imbalance"}, {3, "steps"}}) {
    const std::string out = policy + std::to_string(ranks);
    const auto o = mpi(ranks, {"run", scene, "-o", out, "-q", "--repartition", policy}, sets);
    ASSERT_EQ(o.code, 0) << o.err;
    expect_same_outputs(dir_ / "serial", dir_ / out, "kalthoff_winkler_2d_adaptive");
    const auto d = read_json(dir_ / out / "summary.json").at("distribution");
    EXPECT_LE(d.at("imbalance").get<double>(), 1.1) << out;
    if (policy == "events") {
      EXPECT_GE(d.at("repartitions").get<int>(), 17) << out;
    }
    EXPECT_TRUE(read_json(dir_ / out / "summary.json").contains("time_levels")) << out;
  }
}

TEST_F(MpiCli, BothPartitionersGiveTheSameBits) {
  const auto ref = run_plate("ref", {}, {"time.steps=120"});
  const auto o =
      mpi(3, {"run", "plate.yaml", "-o", "hsfc", "-q", "--partition", "hsfc"}, {"time.steps=120"});
  ASSERT_EQ(o.code, 0) << o.err;
  expect_same_outputs(ref, dir_ / "hsfc", "plate");
}

TEST_F(MpiCli, RestartOnAnotherRankCountContinuesTheUninterruptedRun) {
  const auto ref = run_plate("ref", {}, {"time.steps=120"});
  // Two ranks write a checkpoint at step 60 (kept as checkpoint.prev.bin at the end) ...
  ASSERT_EQ(mpi(2, {"run", "plate.yaml", "-o", "early", "-q"},
                {"time.steps=120", "output.checkpoint_every=60"})
                .code,
            0);
  fs::rename(dir_ / "early" / "checkpoint.prev.bin", dir_ / "early" / "checkpoint.bin");
  // ... which three ranks, and one process, continue to the reference's end.
  const auto three = mpi(3, {"run", "plate.yaml", "-o", "three", "-q", "--restart", "early"},
                         {"time.steps=120", "output.checkpoint_every=60"});
  ASSERT_EQ(three.code, 0) << three.err;
  expect_same_outputs(ref, dir_ / "three", "plate");
  const auto one = dhpd({"run", "plate.yaml", "-o", "one", "-q", "--restart", "early"},
                        {"time.steps=120", "output.checkpoint_every=60"});
  ASSERT_EQ(one.code, 0) << one.err;
  expect_same_outputs(ref, dir_ / "one", "plate");
}

TEST_F(MpiCli, AnUnstableRunStopsOnEveryRankAndKeepsTheSerialRunsLastGoodState) {
  const auto check = dhpd({"check", "plate.yaml"});
  ASSERT_EQ(check.code, 0) << check.err;
  const double stable = std::stod(check.out.substr(check.out.find("stable_dt: ") + 11));
  const std::vector<std::string> sets{fmt::format("time.dt={:.17g}", 3.0 * stable),
                                      "time.check_dt=false", "time.steps=3000"};
  const auto serial = dhpd({"run", "plate.yaml", "-o", "serial", "-q"}, sets);
  ASSERT_EQ(serial.code, 3) << serial.err;
  const auto o = mpi(3, {"run", "plate.yaml", "-o", "np3", "-q"}, sets);
  EXPECT_EQ(o.code, 3) << o.err;
  EXPECT_EQ(count(o.err, "dhpd: unstable run stopped"), 1) << o.err;
  // The same message (but for the folder; mpirun adds its own lines after it) and last good state.
  std::string message = o.err.substr(0, o.err.find('\n'));
  message.replace(message.find("np3/"), 4, "serial/");
  EXPECT_EQ(message + "\n", serial.err);
  for (const char* file : {"history.csv", "plate.pvd"})
    EXPECT_EQ(read_text(dir_ / "serial" / file), read_text(dir_ / "np3" / file)) << file;
  for (const auto& [time, frame] : io::read_pvd((dir_ / "serial" / "plate.pvd").string()))
    EXPECT_TRUE(read_text(dir_ / "serial" / frame) == read_text(dir_ / "np3" / frame)) << frame;
  EXPECT_EQ(read_json(dir_ / "np3" / "summary.json").at("status"), "unstable");
}

/// Starts `mpirun -np RANKS dhpd ARGS...` in `dir` (output discarded, or stderr into `err`);
/// returns mpirun's pid.
pid_t spawn_mpirun(const fs::path& dir, int ranks, const std::vector<std::string>& args,
                   const std::string& err = "/dev/null") {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);  // as MpiCli::mpi, for the child to inherit
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  std::vector<std::string> all{"--oversubscribe",   "-np",   std::to_string(ranks), "-x",
                               "OMP_NUM_THREADS=1", DHPD_BIN};
  all.insert(all.end(), args.begin(), args.end());
  return spawn_program(DHPD_MPIEXEC, dir, all, "/dev/null", err);
}

/// The processes whose parent is `parent` (from /proc/*/stat).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const auto name = entry.path().filename().string();
    if (name.empty() || !std::isdigit(static_cast<unsigned char>(name[0]))) continue;
    const auto stat = read_text(entry.path() / "stat");
    const auto close = stat.rfind(')');  // "pid (comm) state ppid ..."
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 2));
    char state = 0;
    long ppid = 0;
    if (rest >> state >> ppid && ppid == parent) out.push_back(std::stoi(name));
  }
  return out;
}

/// mpirun's exit code, or −1 when it has not finished within `limit` seconds (then it and its
/// ranks are killed).
int wait_at_most(pid_t pid, double limit) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int>(1e3 * limit));
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const auto rank : children_of(pid)) kill(rank, SIGKILL);
  kill(pid, SIGKILL);
  wait_for(pid);
  return -1;
}

TEST_F(MpiCli, SigtermToEveryRankStopsWithACheckpointThatAnyRankCountContinues) {
  // mpirun passes SIGTERM to every rank and kills them a moment later: rank 0 finishes its step
  // and writes the checkpoint (the others help it and ignore the signal themselves).
  write("adaptive.yaml", kAdaptivePlate);
  // 13 times the plate's 12 µs: about a second on two ranks.
  const std::vector<std::string> sets{"time.end=1.6e-4"};
  const auto ref = dhpd({"run", "adaptive.yaml", "-o", "ref", "-q"}, sets);
  ASSERT_EQ(ref.code, 0) << ref.err;
  const auto rows = read_history(dir_ / "ref" / "history.csv").rows.size();
  const pid_t pid = spawn_mpirun(
      dir_, 2, {"run", "adaptive.yaml", "-o", "sig", "-q", "--set", "time.end=1.6e-4"});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const auto text = read_text(dir_ / "sig" / "history.csv");
    if (static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) > rows / 8) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  // As a batch system stops a job step: SIGTERM to every rank at once (mpirun itself passes it on
  // only after a delay of half a second or more, which a loaded machine makes longer).
  for (const auto rank : children_of(pid)) kill(rank, SIGTERM);
  EXPECT_NE(wait_for(pid), 0);
  const auto summary = read_json(dir_ / "sig" / "summary.json");
  ASSERT_EQ(summary.at("status"), "interrupted");
  EXPECT_LT(summary.at("steps").get<long long>(),
            read_json(dir_ / "ref" / "summary.json").at("steps").get<long long>());
  const auto o = mpi(3, {"run", "adaptive.yaml", "-o", "again", "-q", "--restart", "sig"}, sets);
  ASSERT_EQ(o.code, 0) << o.err;
  expect_same_outputs(dir_ / "ref", dir_ / "again", "adaptive");
}

TEST_F(MpiCli, AnEventOverTheMemoryBudgetStopsEveryRankWithExitFour) {
  // Rank 0 alone knows its memory budget: every rank takes its verdict before splitting anything,
  // so a refused event stops the run (before, with a repartition after every event, the other
  // ranks split on and waited in Zoltan for rank 0, which had left).
  write("adaptive.yaml", kAdaptivePlate);
  const std::vector<std::string> args{"run",
                                      "adaptive.yaml",
                                      "-o",
                                      "np2",
                                      "-q",
                                      "--max-memory",
                                      "160",
                                      "--repartition",
                                      "events",
                                      "--set",
                                      "effects.refinement.max_level=5"};
  const pid_t pid = spawn_mpirun(dir_, 2, args, (dir_ / "np2.stderr").string());
  const int code = wait_at_most(pid, 120.0);
  ASSERT_NE(code, -1) << "the ranks hung";
  const auto err = read_text(dir_ / "np2.stderr");
  EXPECT_EQ(code, 4) << err;
  EXPECT_EQ(count(err, "refinement stopped before splitting"), 1) << err;
  EXPECT_EQ(read_json(dir_ / "np2" / "summary.json").at("status"), "resource_limit");
  expect_whole_pvd(dir_ / "np2", "adaptive");
}

TEST_F(MpiCli, BadInputIsReportedOnceByRankZeroWithExitCodeTwo) {
  // A wrong value: every rank meets it, rank 0 alone says so.
  auto o = mpi(3, {"run", "plate.yaml", "-o", "bad"}, {"time.steps=-5"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(count(o.err, "dhpd: error"), 1) << o.err;
  EXPECT_NE(o.err.find("time.steps"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
  // A scene that contradicts itself (correspondence with fracture): named, once.
  o = mpi(2, {"run", "plate.yaml", "-o", "state"}, {"model.family=correspondence"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(count(o.err, "dhpd: error"), 1) << o.err;
  EXPECT_NE(o.err.find("correspondence"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "state"));
  // More ranks than particles.
  write("two.yaml", with_line(kPlate, 8,
                              "  - {shape: box, min: [0, 0], max: [0.001, 0.0005], spacing: "
                              "0.0005, material: glass}"));
  o = mpi(3, {"run", "two.yaml", "-o", "two"}, {"cracks=[]", "boundary_conditions=[]"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(count(o.err, "dhpd: error"), 1) << o.err;
  EXPECT_NE(o.err.find("3 ranks for 2 particles"), std::string::npos) << o.err;
  // A restart from a checkpoint of another scene.
  ASSERT_EQ(mpi(2, {"run", "plate.yaml", "-o", "first", "-q"}).code, 0);
  o = mpi(2, {"run", "plate.yaml", "-o", "again", "--restart", "first"}, {"time.steps=90"});
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_EQ(count(o.err, "dhpd: error"), 1) << o.err;
  EXPECT_FALSE(fs::exists(dir_ / "again"));
}

}  // namespace
}  // namespace dhpd::cli_test
