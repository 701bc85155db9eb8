// Frames written on a thread of their own (docs/outputs.md, "Frames in the background"): the run
// hands a frame over with its own copy of the points and fields and goes on stepping while VTK
// builds, compresses and writes it. Content and file names are those of FrameSeries::write.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tools/output/vtk_writer.hpp"

namespace dhpd::io {

/// At most one frame is in flight: write() waits for the previous frame before handing over the
/// next, so memory holds one extra frame at most and frames land in order. An error writing a
/// frame (IoError) is thrown by the next write(), drain() or entries(); no later frame is
/// written after it. With `background` false every write() writes at once (the same files).
class BackgroundFrames {
 public:
  BackgroundFrames(FrameSeries series, bool background);
  BackgroundFrames(BackgroundFrames&&) noexcept;
  BackgroundFrames& operator=(BackgroundFrames&&) = delete;
  ~BackgroundFrames();  ///< waits for the frame in flight; its error is dropped (call drain())

  void write(double time, std::int64_t step, std::vector<double> points,
             std::vector<PointField> fields);
  /// Waits until every frame handed over is on disk; throws the error of a failed one.
  void drain();
  /// drain() that returns the error message instead of throwing (empty when none).
  std::string drain_quietly();
  /// (time, file) of every frame written (after drain()).
  const std::vector<std::pair<double, std::string>>& entries();
  /// FrameSeries::resume (after drain()).
  void resume(std::vector<std::pair<double, std::string>> entries);

 private:
  struct Worker;
  std::unique_ptr<Worker> w_;
};

}  // namespace dhpd::io
