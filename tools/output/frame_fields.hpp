// The point fields of an output frame, gathered from the simulation by name: at once, or copied
// range by range by the threads of the next step (FrameCopy).
#pragma once
#include <atomic>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "engine/output_fields.hpp"
#include "engine/simulation.hpp"
#include "tools/output/background_frames.hpp"
#include "tools/output/vtk_writer.hpp"

namespace dhpd::io {

/// Reference positions as 3 doubles per particle.
std::vector<double> frame_points(const Simulation& sim);
/// The requested fields (names from scene::default_fields() and scene::optional_fields()).
std::vector<PointField> frame_fields(Simulation& sim, const std::vector<std::string>& names);

/// A frame's points and fields (those of frame_points and frame_fields), the derived fields
/// computed when it is made and the particle store's copied later: range by range by copy()
/// (the threads of the next step, before it changes the state: StepExtras::before_change) or by
/// finish(). `points` and `fields` may be moved away once it is made (to the frame writer):
/// the copies go to their arrays wherever they are.
class FrameCopy {
 public:
  /// `reuse`: the arrays of an earlier frame, filled instead of new ones where a field's name and
  /// type match (BackgroundFrames::take_spent).
  FrameCopy(Simulation& sim, const std::vector<std::string>& names, FrameArrays reuse = {});
  FrameCopy(const FrameCopy&) = delete;
  FrameCopy& operator=(const FrameCopy&) = delete;
  /// Copies particles [begin, end); threads may copy disjoint ranges at once. Nothing after
  /// finish() (the frame may be written and its arrays gone).
  void copy(std::int64_t begin, std::int64_t end);
  /// Copies every particle, unless copy() has covered them all: the store must still hold the
  /// state the frame was made at (no step since, or one that copied every range).
  void finish();

  std::vector<double> points;
  std::vector<PointField> fields;

 private:
  struct Source {
    FieldInfo field;
    std::variant<double*, std::int32_t*> to;
  };
  const ParticleStore& store_;
  std::vector<Source> sources_;
  double* points_to_ = nullptr;
  std::int64_t size_;
  std::atomic<std::int64_t> copied_{0};
  std::atomic<bool> finished_{false};
};

}  // namespace dhpd::io
