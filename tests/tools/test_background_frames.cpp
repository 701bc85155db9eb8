// Frames written in the background (tools/output/background_frames.hpp), on a thread of their own
// or as the side task of the next force pass: the same files, byte for byte, as frames written at
// once; a shared frame waits for its side task (or the next write or drain) and is written once; a
// frame that cannot be written is reported by the next call and stops the series.
#include <fmt/format.h>
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

/// Four frames; in Shared mode the side tasks of frames 0 and 2 run as two force passes would run
/// them, frames 1 and 3 are finished by the next write and by entries().
void write_series(const std::filesystem::path& dir, BackgroundFrames::Mode mode) {
  BackgroundFrames frames(FrameSeries(dir.string(), "plate"), mode);
  const std::size_t n = 500;
  for (int k = 0; k < 4; ++k) {
    std::vector<double> points(3 * n);
    for (std::size_t i = 0; i < 3 * n; ++i) points[i] = 1e-4 * static_cast<double>(i);
    frames.write(1e-6 * k, 10 * k, points, fields_of(k, n));
    const auto name = fmt::format("plate_{:06d}.vtu", k);
    const auto* task = frames.side_task();
    EXPECT_EQ(task != nullptr, mode == BackgroundFrames::Mode::Shared);
    if (mode == BackgroundFrames::Mode::Shared) {
      EXPECT_FALSE(std::filesystem::exists(dir / name)) << "a shared frame waits for its task";
      if (k % 2 == 0) {  // two force passes: the encoding, then the file
        (*task)();
        EXPECT_FALSE(std::filesystem::exists(dir / name)) << "encoded, not yet written";
        ASSERT_NE(frames.side_task(), nullptr) << "the file is left to write";
        (*frames.side_task())();
        EXPECT_TRUE(std::filesystem::exists(dir / name));
        EXPECT_EQ(frames.side_task(), nullptr) << "nothing left in flight";
      }
    }
  }
  EXPECT_EQ(frames.entries().size(), 4u);
}

TEST(BackgroundFrames, WritesTheFilesOfFramesWrittenAtOnce) {
  test::TempDir tmp;
  write_series(tmp.path() / "background", BackgroundFrames::Mode::Thread);
  write_series(tmp.path() / "shared", BackgroundFrames::Mode::Shared);
  write_series(tmp.path() / "at_once", BackgroundFrames::Mode::Now);
  for (const auto* name : {"plate_000000.vtu", "plate_000001.vtu", "plate_000002.vtu",
                           "plate_000003.vtu", "plate.pvd"})
    for (const auto* mode : {"background", "shared"})
      EXPECT_EQ(test::read_file(tmp.path() / mode / name),
                test::read_file(tmp.path() / "at_once" / name))
          << mode << " " << name;
}

TEST(BackgroundFrames, AFailedFrameIsReportedAndStopsTheSeries) {
  for (const auto mode : {BackgroundFrames::Mode::Thread, BackgroundFrames::Mode::Shared}) {
    test::TempDir tmp;
    const auto dir = tmp.path() / "frames";
    BackgroundFrames frames(FrameSeries(dir.string(), "plate"), mode);
    std::filesystem::create_directories(dir / "plate_000000.vtu");  // the frame's name is taken
    frames.write(0.0, 0, std::vector<double>(3, 0.0), fields_of(0, 1));
    if (const auto* task = frames.side_task()) (*task)();  // the error stays with the frames
    EXPECT_THROW(frames.drain(), IoError);
    EXPECT_NE(frames.drain_quietly().find("plate_000000.vtu"), std::string::npos);
    EXPECT_THROW(frames.write(1.0, 1, std::vector<double>(3, 0.0), fields_of(1, 1)), IoError);
    EXPECT_FALSE(std::filesystem::exists(dir / "plate_000001.vtu"));
  }
}

TEST(BackgroundFrames, ListsTheFrameInFlightAsItWillBeWritten) {
  test::TempDir tmp;
  BackgroundFrames shared(FrameSeries((tmp.path() / "s").string(), "plate"),
                          BackgroundFrames::Mode::Shared);
  EXPECT_FALSE(shared.entries_once_written()) << "nothing in flight";
  for (int k = 0; k < 3; ++k) {
    shared.write(1e-6 * k, k, std::vector<double>(6, 0.0), fields_of(k, 2));
    const auto listed = shared.entries_once_written();
    ASSERT_TRUE(listed);
    EXPECT_EQ(*listed, shared.entries()) << "frame " << k;
  }
  BackgroundFrames thread(FrameSeries((tmp.path() / "t").string(), "plate"),
                          BackgroundFrames::Mode::Thread);
  thread.write(0.0, 0, std::vector<double>(6, 0.0), fields_of(0, 2));
  EXPECT_FALSE(thread.entries_once_written()) << "only shared frames are predicted";
}

TEST(BackgroundFrames, HandsBackTheArraysOfTheFrameWritten) {
  test::TempDir tmp;
  BackgroundFrames frames(FrameSeries(tmp.path().string(), "plate"),
                          BackgroundFrames::Mode::Shared);
  EXPECT_TRUE(frames.take_spent().points.empty()) << "no frame written yet";
  frames.write(0.0, 0, std::vector<double>(30, 0.5), fields_of(1, 10));
  EXPECT_TRUE(frames.take_spent().points.empty()) << "the frame is still in flight";
  frames.drain();
  auto spent = frames.take_spent();
  EXPECT_EQ(spent.points, std::vector<double>(30, 0.5));
  ASSERT_EQ(spent.fields.size(), 2u);
  EXPECT_EQ(spent.fields[0].name, "velocity");
  EXPECT_EQ(std::get<std::vector<double>>(spent.fields[0].values).size(), 30u);
  EXPECT_TRUE(frames.take_spent().points.empty()) << "handed back once";
}

}  // namespace
}  // namespace dhpd::io
