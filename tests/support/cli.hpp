// Shared fixture of the end-to-end command-line tests: runs the real dhpd binary in a fresh
// directory per test (stdout and stderr captured) and reads back what it wrote.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/vtk_read.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::cli_test {

namespace fs = std::filesystem;
using nlohmann::json;

// A 10 mm x 5 mm glass plate (20 x 10 particles) with a pre-crack, held at the bottom and pulled
// at the top. The bad-scene table below edits it by line number.
constexpr const char* kPlate = R"(name: plate
dimension: 2
plane: stress
thickness: 0.001
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 3.8}
body:
  - {shape: box, min: [0, 0], max: [0.01, 0.005], spacing: 0.0005, material: glass}
cracks:
  - [[0.0, 0.0025], [0.004, 0.0025]]
boundary_conditions:
  - region: {shape: box, min: [0, 0], max: [0.01, 0.001]}
    fixed: true
  - region: {shape: box, min: [0, 0.004], max: [0.01, 0.005]}
    velocity: {y: 2.0}
effects: {fracture: true}
time: {steps: 60}
output: {every: 20, history_every: 10, fields: [strain_energy_density, bond_count]}
)";
constexpr int kPlateParticles = 20 * 10;

const char* const kHistoryHeader =
    "step,time,dt,particles,bonds,broken_bonds,kinetic_energy,strain_energy,external_work,"
    "momentum_x,momentum_y,momentum_z";

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// `text` with its 1-based line `line` replaced by `replacement` (which may span lines).
inline std::string with_line(const std::string& text, int line, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, current;
  for (int n = 1; std::getline(in, current); ++n) out += (n == line ? replacement : current) + "\n";
  return out;
}

inline std::string quoted(const std::string& word) {
  std::string out = "'";
  for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct Outcome {
  int code = -1;
  std::string out, err;
};

/// history.csv split into its header and rows of cells.
struct History {
  std::string header;
  std::vector<std::vector<std::string>> rows;
  std::vector<long long> column(std::size_t index) const {
    std::vector<long long> values;
    for (const auto& row : rows) values.push_back(std::stoll(row.at(index)));
    return values;
  }
};

inline History read_history(const fs::path& path) {
  std::istringstream in(read_text(path));
  History h;
  std::getline(in, h.header);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    h.rows.push_back(cells);
  }
  return h;
}

inline json read_json(const fs::path& path) {
  return json::parse(read_text(path));
}

inline bool has_effect(const json& summary, const std::string& name) {
  const auto& effects = summary.at("active_effects");
  return std::find(effects.begin(), effects.end(), name) != effects.end();
}

/// Runs the binary with its working directory in a fresh temporary directory.
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    std::random_device random;
    dir_ = fs::temp_directory_path() /
           ("dhpd_cli_" + name + "_" + std::to_string(getpid()) + "_" + std::to_string(random()));
    fs::create_directories(dir_);
    write("plate.yaml", kPlate);
  }
  void TearDown() override {
    if (HasFailure()) {
      std::cerr << "kept the test directory " << dir_ << "\n";
      return;
    }
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  /// Runs `dhpd ARGS... --set S...` in the test directory (or `program ARGS...`, e.g. a shell
  /// that sets limits first).
  Outcome dhpd(const std::vector<std::string>& args, const std::vector<std::string>& sets = {},
               const std::string& program = DHPD_BIN) {
    const fs::path stem = dir_ / ("dhpd_" + std::to_string(++calls_));
    const fs::path out = fs::path(stem).replace_extension("stdout");
    const fs::path err = fs::path(stem).replace_extension("stderr");
    std::ostringstream command;
    command << "cd " << quoted(dir_.string()) << " && " << quoted(program);
    for (const auto& a : args) command << ' ' << quoted(a);
    for (const auto& s : sets) command << " --set " << quoted(s);
    command << " >" << quoted(out.string()) << " 2>" << quoted(err.string()) << " </dev/null";
    const int status = std::system(command.str().c_str());
    Outcome o;
    o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    o.out = read_text(out);
    o.err = read_text(err);
    fs::remove(out);
    fs::remove(err);
    return o;
  }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }

  /// `dhpd run plate.yaml -o OUT -q EXTRA... --set S...`; expects exit 0.
  fs::path run_plate(const std::string& out, const std::vector<std::string>& extra,
                     const std::vector<std::string>& sets = {}) {
    std::vector<std::string> args{"run", "plate.yaml", "-o", out, "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto o = dhpd(args, sets);
    EXPECT_EQ(o.code, 0) << o.err;
    EXPECT_EQ(o.out, "");
    return dir_ / out;
  }

  fs::path dir_;
  int calls_ = 0;
};

}  // namespace dhpd::cli_test
