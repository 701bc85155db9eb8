// Frames written while the run goes on (docs/outputs.md, "Frames in the background"): the run
// hands a frame over with its own copy of the points and fields and goes on stepping while the
// frame is encoded, compressed and written, either on a thread of its own or by one thread of the
// next two steps' force passes (SideTasks: the encoding, then the file). Content and file names
// are those of FrameSeries::write.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/base/parallel.hpp"
#include "tools/output/vtk_writer.hpp"

namespace dhpd::io {

/// A frame's points (3 doubles per particle) and fields.
struct FrameArrays {
  std::vector<double> points;
  std::vector<PointField> fields;
};

/// At most one frame is in flight: write() waits for (or finishes) the previous frame before
/// handing over the next, so memory holds one extra frame at most and frames land in order. An
/// error writing a frame (IoError) is thrown by the next write(), drain() or entries(); no later
/// frame is written after it.
class BackgroundFrames {
 public:
  /// Where a frame handed over is written: at once (Now), on a thread of its own (Thread: for a
  /// spare core), or by the next step's force pass (Shared: pass side_task() to the step; for a
  /// team on every core, where a thread of its own would take a core from the team).
  enum class Mode { Now, Thread, Shared };
  BackgroundFrames(FrameSeries series, Mode mode);
  /// Thread when `background`, else Now.
  BackgroundFrames(FrameSeries series, bool background)
      : BackgroundFrames(std::move(series), background ? Mode::Thread : Mode::Now) {}
  BackgroundFrames(BackgroundFrames&&) noexcept;
  BackgroundFrames& operator=(BackgroundFrames&&) = delete;
  ~BackgroundFrames();  ///< waits for the frame in flight; its error is dropped (call drain())

  /// Hands a frame over. `complete`, when given, finishes filling `points` and `fields` (their
  /// buffers, wherever the vectors are moved): Shared calls it where the frame is encoded, so the
  /// run's next step may fill them first (io::FrameCopy); the other modes call it at once.
  void write(double time, std::int64_t step, std::vector<double> points,
             std::vector<PointField> fields, std::function<void()> complete = {});
  /// Shared: the next half of the work of the frame in flight (its encoding, then its file), for
  /// one thread of the next force pass (nullptr when no frame is in flight; valid until the next
  /// call of any other member). Other modes: nullptr.
  const SideTask* side_task() const;
  /// Whether frames go to the next force pass (Mode::Shared).
  bool shared() const;
  /// Waits until every frame handed over is on disk; throws the error of a failed one.
  void drain();
  /// drain() that returns the error message instead of throwing (empty when none).
  std::string drain_quietly();
  /// (time, file) of every frame written (after drain()).
  const std::vector<std::pair<double, std::string>>& entries();
  /// Shared with a frame in flight and no frame failed: what entries() will be once it is on
  /// disk, without waiting for it (the run's last checkpoint is written beside it). Otherwise
  /// nullopt.
  std::optional<std::vector<std::pair<double, std::string>>> entries_once_written() const;
  /// Shared: the arrays of the last frame written (once it is on disk), for the next frame to
  /// fill instead of new ones (allocating and clearing them took the thread that makes frames
  /// about 0.2 ms a frame on the default scene); empty otherwise or when taken already.
  FrameArrays take_spent();
  /// FrameSeries::resume (after drain()).
  void resume(std::vector<std::pair<double, std::string>> entries);

 private:
  struct Worker;
  std::unique_ptr<Worker> w_;
};

}  // namespace dhpd::io
