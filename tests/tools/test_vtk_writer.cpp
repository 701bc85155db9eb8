// Round trips of the VTK output: frames and the .pvd collection read back bit for bit (with the
// test-only reader of tests/support/vtk_read.hpp), compressed appended binary data, refused input.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "tests/support/temp_dir.hpp"
#include "tests/support/vtk_read.hpp"
#include "tools/output/vtk_writer.hpp"

namespace {

namespace fs = std::filesystem;
using dhpd::io::PointField;
using dhpd::test::TempDir;

std::string read_text(const fs::path& p) {
  return dhpd::test::read_file(p);
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

// Each compressor writes its own bytes, but the frame VTK reads back is the same, bit for bit.
TEST(VtkWriter, EveryCompressionReadsBackTheSameFrame) {
  using dhpd::io::Compression;
  TempDir tmp;
  const TestFrame frame = make_frame(2, 2000);
  const std::vector<std::pair<Compression, std::string>> kinds{
      {Compression::lz4, "vtkLZ4DataCompressor"},
      {Compression::zlib, "vtkZLibDataCompressor"},
      {Compression::none, ""}};
  std::vector<std::uintmax_t> sizes;
  for (const auto& [compression, compressor] : kinds) {
    const fs::path dir = tmp.path() / std::to_string(sizes.size());
    dhpd::io::FrameSeries series(dir.string(), "plate", {}, compression);
    series.write(frame.time, frame.step, frame.points, frame.fields);
    const fs::path vtu = dir / "plate_000000.vtu";
    expect_frame_equal(frame, dhpd::io::read_frame(vtu.string()));
    const std::string text = read_text(vtu);
    const std::string header = text.substr(0, text.find("<AppendedData"));
    if (compressor.empty())
      EXPECT_EQ(header.find("compressor="), std::string::npos);
    else
      EXPECT_NE(header.find("compressor=\"" + compressor + "\""), std::string::npos);
    sizes.push_back(fs::file_size(vtu));
  }
  EXPECT_LT(sizes[0], sizes[2]);  // LZ4 compresses
  EXPECT_LT(sizes[1], sizes[0]);  // zlib more
}

TEST(VtkWriter, Lz4FramesKeepUnchangedArraysAndEncodeChangedOnesAgain) {
  // The LZ4 writer reuses an array's compressed blocks while its bytes stay the same
  // (tools/output/vtu_lz4.hpp): each frame must still read back as written, when one field
  // changes, when nothing does, and when the particle count (points and cells) changes.
  TempDir tmp;
  dhpd::io::FrameSeries series(tmp.path().string(), "plate", {"glass", "steel"});
  TestFrame frame = make_frame(1, 2000);
  std::vector<TestFrame> written;
  auto put = [&] {
    series.write(frame.time, frame.step, frame.points, frame.fields);
    written.push_back(frame);
  };
  put();
  std::get<std::vector<double>>(frame.fields.front().values)[7] += 1.0;  // one value of one field
  frame.step += 1;
  put();
  frame.time += 1.0;  // nothing but the time
  put();
  frame = make_frame(2, 1500);  // fewer particles
  put();
  for (std::size_t k = 0; k < written.size(); ++k) {
    const auto vtu = tmp.path() / fmt::format("plate_{:06d}.vtu", k);
    const auto back = dhpd::io::read_frame(vtu.string());
    expect_frame_equal(written[k], back);
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
  EXPECT_NE(header.find("compressor=\"vtkLZ4DataCompressor\""), std::string::npos);
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
}  // namespace
