// Checkpoints of a whole run (docs/checkpoint.md): the simulation (engine/
// checkpoint.hpp) plus the run loop's own state: frame schedule position, frames written, bytes
// of each CSV at the checkpoint, crack measurements and counters. A restart with another scene
// or other --set overrides is refused with the first line that differs.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"
#include "tools/measure/crack_measure.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {

class AtomicFile;

/// The run loop's state at a checkpoint (after the step `Simulation::steps_done()`).
struct RunState {
  std::int64_t planned_steps = 0;
  std::uint64_t schedule_position = 0;  ///< frames or frame times of the schedule already due
  std::vector<std::pair<double, std::string>> frames;  ///< (time, file) of the .pvd
  std::uint64_t history_bytes = 0, refinement_bytes = 0, cracks_bytes = 0;
  std::uint64_t relaxation_bytes = 0;  ///< relaxation.csv of a static run
  std::int64_t refinement_events = 0, particles_start = 0;
  double wall_seconds = 0.0;  ///< of the runs before this one
  double rayleigh_speed = 0.0;
  std::string derived_text;                 ///< the derived block of scene.resolved.yaml
  measure::CrackTracker* cracks = nullptr;  ///< with `measure`: written, or read into
};

/// The text a checkpoint compares scenes by: the resolved scene without output.directory and
/// output.checkpoint_every (a restart may write elsewhere and checkpoint at another rate).
std::string checkpoint_scene_text(const scene::Scene& scene);

/// DIR/checkpoint.bin, or the file itself when `where` names one.
std::string checkpoint_path(const std::string& where);

/// Writes the checkpoint atomically; the one it replaces stays as checkpoint.prev.bin (in the
/// same folder) until the new one is complete. Returns its size in bytes.
std::size_t write_checkpoint(const std::string& path, const Simulation& sim, const RunState& state,
                             const std::string& scene_text);

/// write_checkpoint in two parts: stage_checkpoint writes and syncs the whole file under its
/// temporary name; commit() renames it (the old one kept as checkpoint.prev.bin until then) and
/// returns its size. Dropped without commit(), nothing of it stays.
class StagedCheckpoint {
 public:
  StagedCheckpoint(std::string path, std::unique_ptr<AtomicFile> file);
  StagedCheckpoint(StagedCheckpoint&&) noexcept;
  ~StagedCheckpoint();
  std::size_t commit();

 private:
  std::string path_;
  std::unique_ptr<AtomicFile> file_;
};
StagedCheckpoint stage_checkpoint(const std::string& path, const Simulation& sim,
                                  const RunState& state, const std::string& scene_text);

/// Restores `sim` (built from the same scene) and `state` (with `state.cracks` set when the scene
/// measures). Throws InputError (exit 2) when the file is missing, truncated, corrupted, or was
/// written for another scene, other overrides or other particles.
void load_checkpoint(const std::string& path, Simulation& sim, RunState& state,
                     const std::string& scene_text);

/// "at key.path the checkpoint has `a`, this run has `b`" for the first line that differs.
std::string first_difference(const std::string& checkpoint_text, const std::string& run_text);

}  // namespace dhpd
