// Round trips of the text outputs: history.csv rows at full precision, summary.json with every key,
// the progress line.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/temp_dir.hpp"
#include "tools/output/text_outputs.hpp"

namespace {

namespace fs = std::filesystem;
using dhpd::test::TempDir;

std::string read_text(const fs::path& p) {
  return dhpd::test::read_file(p);
}

TEST(HistoryWriter, HeaderAndExactRows) {
  TempDir tmp;
  const fs::path path = tmp.path() / "history.csv";
  dhpd::io::HistoryRow row;
  row.step = 42;
  row.time = 1.0 / 3.0;
  row.dt = 2e-7 + 1e-13;
  row.particles = 1234;
  row.bonds = 98765;
  row.broken_bonds = 17;
  row.kinetic_energy = 0.1 + 0.2;
  row.strain_energy = 1e-300 / 3.0;
  row.external_work = -5.0 / 7.0;
  row.momentum[0] = 1e20 / 3.0;
  row.momentum[1] = -0.0;
  row.momentum[2] = 3.0e-17;
  {
    dhpd::io::HistoryWriter writer(path.string());
    writer.write(row);
    // Flushed per row: readable before the writer is closed.
    EXPECT_NE(read_text(path).find('\n', read_text(path).find('\n') + 1), std::string::npos);
  }
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header,
            "step,time,dt,particles,bonds,broken_bonds,kinetic_energy,strain_energy,"
            "external_work,momentum_x,momentum_y,momentum_z");
  std::getline(in, line);
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
  ASSERT_EQ(cells.size(), 12u);
  EXPECT_EQ(std::stoll(cells[0]), row.step);
  EXPECT_EQ(std::strtod(cells[1].c_str(), nullptr), row.time);
  EXPECT_EQ(std::strtod(cells[2].c_str(), nullptr), row.dt);
  EXPECT_EQ(std::stoll(cells[3]), row.particles);
  EXPECT_EQ(std::stoll(cells[4]), row.bonds);
  EXPECT_EQ(std::stoll(cells[5]), row.broken_bonds);
  EXPECT_EQ(std::strtod(cells[6].c_str(), nullptr), row.kinetic_energy);
  EXPECT_EQ(std::strtod(cells[7].c_str(), nullptr), row.strain_energy);
  EXPECT_EQ(std::strtod(cells[8].c_str(), nullptr), row.external_work);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(std::strtod(cells[9 + c].c_str(), nullptr), row.momentum[c]);
  }
}

TEST(Summary, WritesValidJsonWithAllKeys) {
  TempDir tmp;
  const fs::path path = tmp.path() / "summary.json";
  dhpd::io::Summary s;
  s.scene_name = "plate \"notched\"";
  s.scene_file = "scenes/plate.yaml";
  s.message = "ok";
  s.wall_seconds = 12.5;
  s.steps = 5000;
  s.end_time = 1e-3 / 3.0;
  s.dt = 2e-7;
  s.critical_dt = 3e-7;
  s.particles_start = 100;
  s.particles_end = 99;
  s.bonds = 4000;
  s.broken_bonds = 345;
  s.threads = 2;
  s.active_effects = {"gravity", "contact"};
  s.phases = {{"forces", 8.25}, {"output", 0.5}};
  s.materials = {{"matrix", 80, 3000, 300, 20}, {"inclusion", 19, 1000, 45, 4}};
  dhpd::io::write_summary(path.string(), s);

  const auto j = nlohmann::json::parse(read_text(path));
  for (const char* key : {"scene",
                          "scene_file",
                          "status",
                          "message",
                          "wall_seconds",
                          "steps",
                          "end_time",
                          "dt",
                          "critical_dt",
                          "particles_start",
                          "particles_end",
                          "bonds",
                          "broken_bonds",
                          "bond_updates_per_second",
                          "particle_steps_per_second",
                          "threads",
                          "active_effects",
                          "seconds_per_phase",
                          "materials",
                          "allocated_bytes",
                          "bytes_per_particle",
                          "bytes_per_directed_bond"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["scene"], s.scene_name);
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["steps"].get<std::int64_t>(), 5000);
  EXPECT_EQ(j["end_time"].get<double>(), s.end_time);
  EXPECT_EQ(j["active_effects"], (std::vector<std::string>{"gravity", "contact"}));
  EXPECT_EQ(j["seconds_per_phase"]["forces"].get<double>(), 8.25);
  EXPECT_EQ(j["materials"]["inclusion"]["broken_bonds"].get<std::int64_t>(), 45);
  EXPECT_EQ(j["materials"]["matrix"]["damaged_particles"].get<std::int64_t>(), 20);
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator{}), 1);
}

TEST(Progress, DisabledPrintsNothing) {
  dhpd::io::Progress progress(10, false);
  ::testing::internal::CaptureStderr();
  progress.update(5, 1e-6, 3, 1.0);
  progress.finish();
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(Progress, EnabledThrottlesAndEndsLine) {
  dhpd::io::Progress progress(5000, true);
  ::testing::internal::CaptureStderr();
  progress.update(1200, 1.234e-5, 345, 1.0);
  progress.update(1201, 1.235e-5, 345, 1.1);  // within 0.25 s: skipped
  progress.finish();
  const std::string out = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(out.find("\rstep 1200/5000  t=1.234e-05 s  ETA 3 s  broken 345"), std::string::npos);
  EXPECT_EQ(out.find("1201"), std::string::npos);
  EXPECT_EQ(out.back(), '\n');
}

TEST(Progress, TimeEndedRunsCountInSimulatedTimeWhateverTheSteps) {
  // Refinement halves dt: the run does more steps than planned (441 of 233 once printed
  // "ETA 0 s"). At 1 µs of simulated time per wall second, 6 µs before the end is 6 s away.
  dhpd::io::Progress progress(233, false, 0, 1e-5);
  EXPECT_EQ(progress.eta(100, 1e-6, 1.0), "--");  // no rate yet
  EXPECT_EQ(progress.eta(441, 4e-6, 4.0), "6");   // past the planned steps, not "0"
  EXPECT_EQ(progress.eta(900, 1e-5, 10.0), "0");
  // A step-ended run: the steps left at the rate so far.
  dhpd::io::Progress steps(1000, false);
  EXPECT_EQ(steps.eta(250, 0.0, 5.0), "15");
}

}  // namespace
