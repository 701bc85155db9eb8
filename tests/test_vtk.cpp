// Round trips of the run outputs: VTK frames + pvd collection, history.csv and summary.json.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "tools/output/text_outputs.hpp"
#include "tools/output/vtk_writer.hpp"

namespace {

namespace fs = std::filesystem;
using dhpd::io::PointField;

/// A fresh directory under the system temp dir, removed again when the test ends.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("dhpd_" + std::string(info->name()) + "_" +
                                         std::to_string(getpid()) + "_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct TestFrame {
  double time;
  std::int64_t step;
  std::vector<double> points;
  std::vector<PointField> fields;
};

/// Values chosen so that anything short of 17 significant digits would lose bits.
TestFrame make_frame(int k, int n) {
  TestFrame f;
  f.time = k == 0 ? 1.0 / 3.0 : 2e-7 * k + 1e-13;
  f.step = 1234567890123LL * (k + 1);
  std::vector<double> disp, damage;
  std::vector<std::int32_t> material, id;
  for (int i = 0; i < n; ++i) {
    const double x = 1.0 / (i + 3.0) + k * 0.1;
    f.points.insert(f.points.end(), {x, std::sqrt(2.0) * i, -x / 7.0});
    disp.insert(disp.end(), {1e-9 * i / 3.0, -0.7 / (i + 1), 1.0 / 3.0 + k});
    damage.push_back(i / 49.0);
    material.push_back(i % 3 - 1);
    id.push_back(1000000 * k + i);
  }
  f.fields.push_back({"displacement", 3, disp});
  f.fields.push_back({"damage", 1, damage});
  f.fields.push_back({"material", 1, material});
  f.fields.push_back({"id", 1, id});
  return f;
}

std::vector<double> as_doubles(const PointField& field) {
  if (const auto* d = std::get_if<std::vector<double>>(&field.values)) return *d;
  const auto& v = std::get<std::vector<std::int32_t>>(field.values);
  return {v.begin(), v.end()};
}

void expect_frame_equal(const TestFrame& expected, const dhpd::io::Frame& got) {
  EXPECT_EQ(got.time, expected.time);
  EXPECT_EQ(got.step, expected.step);
  EXPECT_EQ(got.points, expected.points);
  ASSERT_EQ(got.fields.size(), expected.fields.size());
  for (const PointField& field : expected.fields) {
    auto it = got.fields.find(field.name);
    ASSERT_NE(it, got.fields.end()) << field.name;
    EXPECT_EQ(it->second.first, field.components) << field.name;
    EXPECT_EQ(it->second.second, as_doubles(field)) << field.name;
    const bool is_int = std::holds_alternative<std::vector<std::int32_t>>(field.values);
    EXPECT_EQ(got.field_types.at(field.name), is_int ? "int" : "double") << field.name;
  }
}

TEST(VtkWriter, RoundTripFramesAndCollection) {
  TempDir tmp;
  const fs::path dir = tmp.path() / "frames";  // does not exist yet: write() creates it
  dhpd::io::FrameSeries series(dir.string(), "plate");
  std::vector<TestFrame> frames;
  for (int k = 0; k < 3; ++k) {
    frames.push_back(make_frame(k, 50));
    series.write(frames[k].time, frames[k].step, frames[k].points, frames[k].fields);
  }
  EXPECT_EQ(series.frames_written(), 3u);

  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  ASSERT_EQ(pvd.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const std::string name = "plate_00000" + std::to_string(k) + ".vtu";
    EXPECT_EQ(pvd[k].first, frames[k].time);
    EXPECT_EQ(pvd[k].second, name);
    expect_frame_equal(frames[k], dhpd::io::read_frame((dir / name).string()));
  }

  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"plate.pvd", "plate_000000.vtu", "plate_000001.vtu",
                                             "plate_000002.vtu"}));

  const std::string vtu = read_text(dir / "plate_000001.vtu");
  const std::string header = vtu.substr(0, vtu.find("<AppendedData"));
  EXPECT_NE(header.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(header.find("format=\"appended\""), std::string::npos);
  EXPECT_EQ(header.find("format=\"ascii\""), std::string::npos);
  EXPECT_NE(vtu.find("<AppendedData encoding=\"raw\">"), std::string::npos);
  EXPECT_NE(header.find("type=\"Float64\" Name=\"Points\""), std::string::npos);
}

TEST(VtkWriter, RejectsMismatchedFieldAndMissingFile) {
  TempDir tmp;
  dhpd::io::FrameSeries series(tmp.path().string(), "bad");
  const std::vector<double> points = {0, 0, 0, 1, 1, 1};
  const std::vector<PointField> fields = {{"damage", 1, std::vector<double>{0.5}}};
  EXPECT_ANY_THROW(series.write(0.0, 0, points, fields));
  EXPECT_EQ(series.frames_written(), 0u);
  EXPECT_THROW(dhpd::io::read_frame((tmp.path() / "missing.vtu").string()), std::runtime_error);
  EXPECT_THROW(dhpd::io::read_pvd((tmp.path() / "missing.pvd").string()), std::runtime_error);
  // An output "directory" that is a regular file is an I/O failure naming the path.
  std::ofstream(tmp.path() / "blocker") << "x";
  dhpd::io::FrameSeries blocked((tmp.path() / "blocker").string(), "f");
  try {
    blocked.write(0.0, 0, points, {});
    ADD_FAILURE() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("blocker"), std::string::npos) << e.what();
  }
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
  for (const char* key :
       {"scene", "scene_file", "status", "message", "wall_seconds", "steps", "end_time", "dt",
        "critical_dt", "particles_start", "particles_end", "bonds", "broken_bonds",
        "bond_updates_per_second", "particle_steps_per_second", "threads", "active_effects",
        "seconds_per_phase", "materials"}) {
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

}  // namespace
