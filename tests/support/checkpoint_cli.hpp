// Shared by the checkpoint command-line tests: a refining, measured 2D fracture scene, starting
// dhpd as a child process (to signal or kill it), and comparing two run folders file by file.
#pragma once
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "tests/support/cli.hpp"

namespace dhpd::cli_test {

// A 20 mm x 8 mm glass plate at 0.5 mm with an 8 mm pre-crack, pulled by tractions: the crack
// runs, damaged particles split (refinement.csv), the tip is measured (cracks.csv); 271 steps,
// about a second. Checkpoints every 40 steps.
constexpr const char* kAdaptivePlate = R"(name: adaptive
dimension: 2
plane: stress
thickness: 0.001
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
body:
  - {shape: box, min: [0, 0], max: [0.02, 0.008], spacing: 0.0005, material: glass}
partial_volume: linear
cracks:
  - [[0.0, 0.004], [0.008, 0.004]]
no_fail:
  - {shape: box, min: [0, 0], max: [0.02, 0.001]}
  - {shape: box, min: [0, 0.007], max: [0.02, 0.008]}
boundary_conditions:
  - region: {shape: box, min: [0, 0.0065], max: [0.02, 0.008]}
    traction: [0, 30.0e6]
    normal: y
  - region: {shape: box, min: [0, 0], max: [0.02, 0.0015]}
    traction: [0, -30.0e6]
    normal: y
effects:
  fracture: true
  refinement: {trigger: {damage: 0.05}, buffer: 0.5, max_level: 1, check_every: 10}
time: {end: 1.2e-5, safety: 0.8, stable_step: bound}
output: {frames: 12, history_every: 5, checkpoint_every: 40}
measure:
  every: 10
  tips:
    - {name: notch, at: [0.008, 0.004], direction: [1, 0]}
)";

/// summary.json keys that measure the process rather than the physics: wall clock, and memory
/// (a restarted process's arrays and scratch have other capacities); they differ between runs.
inline bool wall_clock_key(const std::string& key) {
  return key == "wall_seconds" || key == "bond_updates_per_second" ||
         key == "particle_steps_per_second" || key == "seconds_per_phase" ||
         key == "command_line" || key == "peak_memory_mb" || key == "allocated_bytes" ||
         key == "bytes_per_particle" || key == "bytes_per_directed_bond" || key == "threads" ||
         key == "ranks" || key == "distribution";
}

/// refinement.csv without its wall-clock columns `seconds` (14th) and `resort_seconds` (16th).
inline std::string without_wall_clock_columns(const std::string& csv) {
  std::istringstream in(csv);
  std::string out;
  std::vector<bool> keep;  // by the header's names: `seconds` and `resort_seconds` are wall time
  for (std::string line; std::getline(in, line);) {
    std::istringstream row(line);
    std::size_t column = 0;
    for (std::string cell; std::getline(row, cell, ','); ++column) {
      if (keep.size() <= column) keep.push_back(cell != "seconds" && cell != "resort_seconds");
      if (keep[column]) out += cell + ",";
    }
    out += "\n";
  }
  return out;
}

/// Starts `program ARGS` (a path) in `dir` with stdout and stderr into the given files
/// (discarded unless given); returns the child's pid.
inline pid_t spawn_program(const std::string& program, const fs::path& dir,
                           const std::vector<std::string>& args,
                           const std::string& out = "/dev/null",
                           const std::string& err = "/dev/null") {
  std::vector<std::string> all{program};
  all.insert(all.end(), args.begin(), args.end());
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    if (!freopen(out.c_str(), "w", stdout) || !freopen(err.c_str(), "w", stderr)) _exit(127);
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(program.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

/// Starts `dhpd ARGS` in `dir` (spawn_program of the binary); returns the child's pid.
inline pid_t spawn_dhpd(const fs::path& dir, const std::vector<std::string>& args,
                        const std::string& out = "/dev/null",
                        const std::string& err = "/dev/null") {
  return spawn_program(DHPD_BIN, dir, args, out, err);
}

/// The exit code of the child, or 128 + the signal that killed it.
inline int wait_for(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// The .pvd parses, is complete, and every frame it lists exists and reads back with its step.
inline void expect_whole_pvd(const fs::path& dir, const std::string& name) {
  const auto pvd = dir / (name + ".pvd");
  if (!fs::exists(pvd)) return;  // killed before the first frame
  const auto text = read_text(pvd);
  EXPECT_NE(text.find("</VTKFile>"), std::string::npos) << pvd;
  const auto entries = io::read_pvd(pvd.string());
  for (const auto& [time, file] : entries) {
    io::Frame frame;
    ASSERT_NO_THROW(frame = io::read_frame((dir / file).string())) << file;
    EXPECT_EQ(frame.time, time) << file;
    EXPECT_FALSE(frame.points.empty()) << file;
  }
}

/// The outputs of `b` equal those of `a`: CSVs, .pvd and frames byte for byte (refinement.csv
/// without its wall-clock columns), summary.json except its wall-clock and process keys.
inline void expect_same_outputs(const fs::path& a, const fs::path& b, const std::string& name) {
  for (const char* csv : {"history.csv", "cracks.csv"}) {
    if (fs::exists(a / csv)) {
      EXPECT_EQ(read_text(a / csv), read_text(b / csv)) << csv;
    }
  }
  if (fs::exists(a / "refinement.csv")) {
    EXPECT_EQ(without_wall_clock_columns(read_text(a / "refinement.csv")),
              without_wall_clock_columns(read_text(b / "refinement.csv")));
  }
  const auto pvd = name + ".pvd";
  EXPECT_EQ(read_text(a / pvd), read_text(b / pvd));
  for (const auto& [time, file] : io::read_pvd((a / pvd).string()))
    EXPECT_TRUE(read_text(a / file) == read_text(b / file)) << file << " differs";
  auto sa = read_json(a / "summary.json"), sb = read_json(b / "summary.json");
  for (const auto& [key, value] : sa.items()) {
    if (!wall_clock_key(key)) {
      EXPECT_EQ(value, sb[key]) << "summary.json " << key;
    }
  }
}

}  // namespace dhpd::cli_test
