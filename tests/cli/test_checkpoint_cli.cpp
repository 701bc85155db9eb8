// Checkpoint and restart through the binary: checkpoints at the end and every N steps, restarts
// equal to uninterrupted runs, refused checkpoints (exit 2, nothing written), SIGTERM / SIGINT
// (exit 143 / 130, a valid .pvd, a checkpoint) and kill -9 at random moments.
#include <random>

#include "tests/support/checkpoint_cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

class CheckpointCli : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    write("adaptive.yaml", kAdaptivePlate);
  }
  /// `dhpd run adaptive.yaml -o OUT -q ARGS...`
  Outcome run_adaptive(const std::string& out, const std::vector<std::string>& args = {},
                       const std::vector<std::string>& sets = {}) {
    std::vector<std::string> all{"run", "adaptive.yaml", "-o", out, "-q"};
    all.insert(all.end(), args.begin(), args.end());
    return dhpd(all, sets);
  }
  /// The reference: the adaptive plate run without interruption.
  fs::path reference() {
    const auto o = run_adaptive("ref");
    EXPECT_EQ(o.code, 0) << o.err;
    return dir_ / "ref";
  }
};

TEST_F(CheckpointCli, EveryRunEndsWithACheckpointAndKeepsThePreviousOne) {
  const auto dir = run_plate("a", {});
  EXPECT_TRUE(fs::exists(dir / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(dir / "checkpoint.bin.tmp"));
  const auto every = run_plate("b", {}, {"output.checkpoint_every=25"});
  EXPECT_TRUE(fs::exists(every / "checkpoint.prev.bin"));  // the one of step 50
  const auto none = run_plate("c", {}, {"output.checkpoint_every=0"});
  EXPECT_FALSE(fs::exists(none / "checkpoint.bin"));
  // A new run in an old run's folder is refused; with --overwrite it removes that run's
  // checkpoints with the rest of its outputs.
  const auto refused = dhpd({"run", "plate.yaml", "-o", "b", "-q"}, {"output.checkpoint_every=0"});
  EXPECT_EQ(refused.code, 2);
  EXPECT_TRUE(fs::exists(every / "checkpoint.bin"));
  run_plate("b", {"--overwrite"}, {"output.checkpoint_every=0"});
  EXPECT_FALSE(fs::exists(every / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(every / "checkpoint.prev.bin"));
  const auto bad = dhpd({"run", "plate.yaml", "-o", "d"}, {"output.checkpoint_every=-3"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("output.checkpoint_every"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("-3"), std::string::npos) << bad.err;
}

TEST_F(CheckpointCli, RunOfPlannedStepsRestartsFromItsStep30Checkpoint) {
  const auto ref = run_plate("ref", {});
  run_plate("early", {}, {"output.checkpoint_every=30"});  // checkpoint.prev.bin: step 30 of 60
  fs::rename(dir_ / "early" / "checkpoint.prev.bin", dir_ / "early" / "checkpoint.bin");
  const auto o = dhpd({"run", "plate.yaml", "-o", "new", "-q", "--restart", "early"});
  ASSERT_EQ(o.code, 0) << o.err;
  expect_same_outputs(ref, dir_ / "new", "plate");
  EXPECT_EQ(read_history(dir_ / "new" / "history.csv").rows.size(), 7u);  // steps 0, 10, ..., 60
}

TEST_F(CheckpointCli, RestartFromAMidRunCheckpointEqualsTheUninterruptedRun) {
  const auto ref = reference();
  const auto history = read_history(ref / "history.csv");
  ASSERT_GT(history.column(5).back(), 100) << "the crack runs";
  const auto events = read_text(ref / "refinement.csv");
  ASSERT_GT(std::count(events.begin(), events.end(), '\n'), 3) << "refinement events";
  // Checkpoints do not change a run: every 120 steps gives the reference's outputs, and its
  // checkpoint.prev.bin is the one of step 240, mid-run (the restart cuts back every CSV and
  // rewrites the frames after it).
  ASSERT_EQ(run_adaptive("early", {}, {"output.checkpoint_every=120"}).code, 0);
  expect_same_outputs(ref, dir_ / "early", "adaptive");
  fs::rename(dir_ / "early" / "checkpoint.prev.bin", dir_ / "early" / "checkpoint.bin");
  for (const std::string out : {"new", "early"}) {  // into another folder, and in place
    const auto o = run_adaptive(out, {"--restart", "early"});
    ASSERT_EQ(o.code, 0) << o.err;
    expect_same_outputs(ref, dir_ / out, "adaptive");
  }
}

TEST_F(CheckpointCli, DamagedMissingOrForeignCheckpointsAreRefusedBeforeAnythingIsWritten) {
  run_plate("a", {});
  const auto refused = [&](const std::string& from, const std::string& expected,
                           const std::vector<std::string>& sets = {}) {
    const auto o = dhpd({"run", "plate.yaml", "-o", "r", "--restart", from}, sets);
    EXPECT_EQ(o.code, 2) << from << ": " << o.err;
    EXPECT_NE(o.err.find(expected), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir_ / "r")) << "something was written for " << from;
  };
  refused("nowhere", "no checkpoint");
  refused("a", "time.safety", {"time.safety=0.4"});
  refused("a", "`safety: 0.5`", {"time.safety=0.4"});
  refused("a", "effects.fracture", {"effects.fracture=false"});
  const auto bytes = read_text(dir_ / "a" / "checkpoint.bin");
  const auto damaged = [&](const std::string& name, const std::string& text) {
    fs::create_directories(dir_ / name);
    for (const auto& f : fs::directory_iterator(dir_ / "a"))
      fs::copy_file(f.path(), dir_ / name / f.path().filename());
    write(name + "/checkpoint.bin", text);
  };
  damaged("cut", bytes.substr(0, bytes.size() - 100));
  refused("cut", "truncated");
  auto flipped = bytes;
  flipped[flipped.size() / 3] ^= 0x20;
  damaged("flipped", flipped);
  refused("flipped", "checksum");
  auto old = bytes;  // the format before one row entry per neighbour pair
  old[8] = 3;
  damaged("old", old);
  refused("old", "format version 3, this dhpd reads version 9");
  damaged("text", "not a checkpoint at all, just some text in a file");
  refused("text", "header");
  damaged("noframe", bytes);
  fs::remove(dir_ / "noframe" / "plate_000001.vtu");
  refused("noframe", "plate_000001.vtu");
  damaged("short", bytes);
  fs::resize_file(dir_ / "short" / "history.csv", 40);
  refused("short", "history.csv is shorter");
}

TEST_F(CheckpointCli, AnUnfinishedPvdIsNotTakenForAWholeOne) {
  const auto dir = run_plate("a", {});
  const auto text = read_text(dir / "plate.pvd");
  EXPECT_EQ(dhpd::io::read_pvd((dir / "plate.pvd").string()).size(), 4u);
  const auto cut = dir_ / "cut.pvd";
  for (std::size_t n = 0; n + 2 < text.size(); n += 7) {  // every prefix short of the last tag
    write("cut.pvd", text.substr(0, n));
    EXPECT_THROW(dhpd::io::read_pvd(cut.string()), std::runtime_error) << n << " bytes";
  }
}

/// Waits (up to a minute) until the run writing into `out` has more than `rows` history rows.
void wait_for_rows(const fs::path& out, std::size_t rows) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const auto text = read_text(out / "history.csv");
    if (static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) > rows) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

/// Starts the adaptive run, waits until history.csv has `rows` rows, sends `signal`.
int interrupt_after(const fs::path& dir, const std::string& out, std::size_t rows, int signal) {
  const pid_t pid = spawn_dhpd(dir, {"run", "adaptive.yaml", "-o", out, "-q"});
  wait_for_rows(dir / out, rows);
  kill(pid, signal);
  return wait_for(pid);
}

TEST_F(CheckpointCli, SigtermAndSigintStopWithACheckpointAndTheRestartMatches) {
  const auto ref = reference();
  const auto total = read_history(ref / "history.csv").rows.size();
  for (const auto& [signal, code] : {std::pair{SIGTERM, 143}, std::pair{SIGINT, 130}}) {
    const std::string out = "sig" + std::to_string(signal);
    ASSERT_EQ(interrupt_after(dir_, out, total / 3, signal), code);
    const auto summary = read_json(dir_ / out / "summary.json");
    EXPECT_EQ(summary.at("status"), "interrupted");
    EXPECT_NE(summary.at("message").get<std::string>().find("--restart"), std::string::npos);
    const auto steps = summary.at("steps").get<std::int64_t>();
    EXPECT_LT(steps, read_json(ref / "summary.json").at("steps").get<std::int64_t>());
    expect_whole_pvd(dir_ / out, "adaptive");
    const auto pvd = dhpd::io::read_pvd((dir_ / out / "adaptive.pvd").string());
    EXPECT_EQ(dhpd::io::read_frame((dir_ / out / pvd.back().second).string()).step, steps)
        << "the final frame is of the last step";
    ASSERT_TRUE(fs::exists(dir_ / out / "checkpoint.bin"));
    const auto o = run_adaptive(out + "r", {"--restart", out});
    ASSERT_EQ(o.code, 0) << o.err;
    expect_same_outputs(ref, dir_ / (out + "r"), "adaptive");
  }
}

TEST_F(CheckpointCli, KillNineAtRandomMomentsLeavesWholeFilesAndRestartsExactly) {
  const auto ref = reference();
  const auto rows = read_history(ref / "history.csv").rows.size();
  // The moment: after a random number of history rows (so it does not depend on how loaded the
  // machine is), then a random 0-30 ms more (anywhere within the writes of a step).
  std::mt19937 random(20261201);
  std::uniform_int_distribution<std::size_t> row(1, rows - 1);
  std::uniform_real_distribution<double> extra(0.0, 0.03);
  // At least 20 trials that kill a run and restart it; a kill before the first checkpoint only
  // checks the .pvd.
  constexpr int kTrials = 20;
  int restarted = 0, attempts = 0, mid_checkpoint = 0, mid_frame = 0;
  for (; restarted < kTrials && attempts < 2 * kTrials; ++attempts) {
    const std::string out = "kill" + std::to_string(attempts);
    const pid_t pid = spawn_dhpd(dir_, {"run", "adaptive.yaml", "-o", out, "-q"});
    wait_for_rows(dir_ / out, row(random));
    std::this_thread::sleep_for(std::chrono::duration<double>(extra(random)));
    kill(pid, SIGKILL);
    const int code = wait_for(pid);
    expect_whole_pvd(dir_ / out, "adaptive");
    for (const auto& f : fs::directory_iterator(dir_ / out)) {  // what the kill interrupted
      mid_checkpoint += f.path().filename() == "checkpoint.bin.tmp" ? 1 : 0;
      mid_frame += f.path().extension() == ".tmp" && f.path().stem().extension() == ".vtu";
    }
    if (!fs::exists(dir_ / out / "checkpoint.bin")) {
      EXPECT_EQ(code, 128 + SIGKILL) << "a finished run leaves a checkpoint";
      continue;  // killed before the first checkpoint
    }
    // Half the trials continue in place, half into a new folder.
    const std::string to = restarted % 2 ? out : out + "r";
    const auto o = run_adaptive(to, {"--restart", out});
    ASSERT_EQ(o.code, 0) << "attempt " << attempts << ": " << o.err;
    expect_same_outputs(ref, dir_ / to, "adaptive");
    ++restarted;
  }
  EXPECT_EQ(restarted, kTrials);
  std::cerr << restarted << " killed runs restarted in " << attempts << " kills; " << mid_checkpoint
            << " killed while writing a checkpoint, " << mid_frame << " while writing a frame\n";
}

}  // namespace
