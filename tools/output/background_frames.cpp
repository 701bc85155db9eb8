// Frames written on a thread of their own (see background_frames.hpp).
#include "tools/output/background_frames.hpp"

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "engine/base/errors.hpp"

namespace dhpd::io {

struct BackgroundFrames::Worker {
  struct Frame {
    double time = 0.0;
    std::int64_t step = 0;
    std::vector<double> points;
    std::vector<PointField> fields;
    std::function<void()> complete;  ///< Shared: fills points and fields before the encoding
  };

  explicit Worker(FrameSeries s) : series(std::move(s)) {}
  FrameSeries series;
  bool shared = false;
  SideTask task;  ///< Shared: writes the pending frame (set once the worker has its address)
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<Frame> pending;  ///< handed over, not yet written
  FrameArrays spent;             ///< Shared: the arrays of the last frame written
  bool encoded = false;          ///< Shared: the pending frame is encoded, its file not written
  bool stop = false;
  std::exception_ptr error;
  std::thread thread;  ///< last: started after every member above exists

  void run() {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return stop || pending.has_value(); });
      if (!pending) return;  // stopped with nothing left
      Frame f = std::move(*pending);
      lock.unlock();
      std::exception_ptr failed;
      try {
        series.write(f.time, f.step, f.points, f.fields);
      } catch (...) {
        failed = std::current_exception();
      }
      lock.lock();
      pending.reset();
      error = failed;
      changed.notify_all();
      if (error) stop = true;  // no frame after a failed one
    }
  }
  /// Shared: the next half of the pending frame here and now, keeping its error: its encoding,
  /// then (at the next call) its file, so a force pass beside it has rows enough to balance it.
  /// No lock: a shared frame is written by the force pass, while the thread that owns the frames
  /// waits for the pass.
  void advance_pending() noexcept {
    if (!pending) return;
    if (!error) {
      try {
        if (!encoded) {
          if (pending->complete) pending->complete();
          series.prepare(pending->time, pending->step, pending->points, pending->fields);
          encoded = true;
          return;
        }
        series.commit();
        spent = {std::move(pending->points), std::move(pending->fields)};
      } catch (...) {
        error = std::current_exception();
      }
    }
    encoded = false;
    pending.reset();
  }
  /// Shared: writes what is left of the pending frame, then throws the error of a failed frame.
  void finish_shared() {
    while (pending) advance_pending();
    if (error) std::rethrow_exception(error);
  }
  /// Waits until nothing is in flight (lock held by the caller).
  void wait_idle(std::unique_lock<std::mutex>& lock) {
    changed.wait(lock, [&] { return !pending.has_value(); });
  }
  void rethrow(std::unique_lock<std::mutex>& lock) {
    wait_idle(lock);
    if (error) std::rethrow_exception(error);
  }
};

BackgroundFrames::BackgroundFrames(FrameSeries series, Mode mode)
    : w_(std::make_unique<Worker>(std::move(series))) {
  if (mode == Mode::Thread) w_->thread = std::thread([w = w_.get()] { w->run(); });
  if (mode == Mode::Shared) {
    w_->shared = true;
    w_->task = [w = w_.get()] { w->advance_pending(); };
  }
}

BackgroundFrames::BackgroundFrames(BackgroundFrames&&) noexcept = default;

BackgroundFrames::~BackgroundFrames() {
  if (w_ && w_->shared)
    while (w_->pending) w_->advance_pending();
  if (!w_ || !w_->thread.joinable()) return;
  {
    std::lock_guard lock(w_->mutex);
    w_->stop = true;
  }
  w_->changed.notify_all();
  w_->thread.join();
}

void BackgroundFrames::write(double time, std::int64_t step, std::vector<double> points,
                             std::vector<PointField> fields, std::function<void()> complete) {
  if (w_->shared) {
    w_->finish_shared();
    w_->pending =
        Worker::Frame{time, step, std::move(points), std::move(fields), std::move(complete)};
    return;
  }
  if (complete) complete();
  if (!w_->thread.joinable()) {
    w_->series.write(time, step, points, fields);
    return;
  }
  std::unique_lock lock(w_->mutex);
  w_->rethrow(lock);
  w_->pending = Worker::Frame{time, step, std::move(points), std::move(fields), {}};
  w_->changed.notify_all();
}

bool BackgroundFrames::shared() const {
  return w_->shared;
}

const SideTask* BackgroundFrames::side_task() const {
  return w_->shared && w_->pending ? &w_->task : nullptr;
}

void BackgroundFrames::drain() {
  if (w_->shared) {
    w_->finish_shared();
    return;
  }
  if (!w_->thread.joinable()) return;
  std::unique_lock lock(w_->mutex);
  w_->rethrow(lock);
}

std::string BackgroundFrames::drain_quietly() {
  try {
    drain();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

const std::vector<std::pair<double, std::string>>& BackgroundFrames::entries() {
  drain();
  return w_->series.entries();
}

FrameArrays BackgroundFrames::take_spent() {
  return std::exchange(w_->spent, {});
}

std::optional<std::vector<std::pair<double, std::string>>> BackgroundFrames::entries_once_written()
    const {
  if (!w_->shared || !w_->pending || w_->error) return std::nullopt;
  auto out = w_->series.entries();
  out.emplace_back(w_->pending->time, w_->series.next_file());
  return out;
}

void BackgroundFrames::resume(std::vector<std::pair<double, std::string>> entries) {
  drain();
  w_->series.resume(std::move(entries));
}

}  // namespace dhpd::io
