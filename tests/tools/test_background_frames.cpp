// Frames written in the background (tools/output/background_frames.hpp): the same files, byte for
// byte, as frames written at once; a frame that cannot be written is reported by the next call and
// stops the series.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "engine/base/errors.hpp"
#include "tests/support/temp_dir.hpp"
#include "tools/output/background_frames.hpp"

namespace dhpd::io {
namespace {

std::vector<PointField> fields_of(int frame, std::size_t n) {
  std::vector<double> v(3 * n);
  std::vector<std::int32_t> id(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) v[3 * i + a] = 1e-3 * frame * static_cast<double>(i + a);
    id[i] = static_cast<std::int32_t>(i);
  }
  return {{"velocity", 3, v}, {"id", 1, id}};
}

void write_series(const std::filesystem::path& dir, bool background) {
  BackgroundFrames frames(FrameSeries(dir.string(), "plate"), background);
  const std::size_t n = 500;
  for (int k = 0; k < 4; ++k) {
    std::vector<double> points(3 * n);
    for (std::size_t i = 0; i < 3 * n; ++i) points[i] = 1e-4 * static_cast<double>(i);
    frames.write(1e-6 * k, 10 * k, points, fields_of(k, n));
  }
  EXPECT_EQ(frames.entries().size(), 4u);
}

TEST(BackgroundFrames, WritesTheFilesOfFramesWrittenAtOnce) {
  test::TempDir tmp;
  write_series(tmp.path() / "background", true);
  write_series(tmp.path() / "at_once", false);
  for (const auto* name : {"plate_000000.vtu", "plate_000003.vtu", "plate.pvd"})
    EXPECT_EQ(test::read_file(tmp.path() / "background" / name),
              test::read_file(tmp.path() / "at_once" / name))
        << name;
}

TEST(BackgroundFrames, AFailedFrameIsReportedAndStopsTheSeries) {
  test::TempDir tmp;
  const auto dir = tmp.path() / "frames";
  BackgroundFrames frames(FrameSeries(dir.string(), "plate"), true);
  std::filesystem::create_directories(dir / "plate_000000.vtu");  // the frame's name is taken
  frames.write(0.0, 0, std::vector<double>(3, 0.0), fields_of(0, 1));
  EXPECT_THROW(frames.drain(), IoError);
  EXPECT_NE(frames.drain_quietly().find("plate_000000.vtu"), std::string::npos);
  EXPECT_THROW(frames.write(1.0, 1, std::vector<double>(3, 0.0), fields_of(1, 1)), IoError);
  EXPECT_FALSE(std::filesystem::exists(dir / "plate_000001.vtu"));
}

}  // namespace
}  // namespace dhpd::io
