// A whole run of a scene: validation first, then outputs (resolved scene, frames, history,
// summary). Nothing is written before the scene and the simulation have been fully checked.
#pragma once
#include <optional>
#include <stdexcept>
#include <string>

#include "tools/scene/scene.hpp"

namespace dhpd {

struct RunOptions {
  std::optional<std::string> output_directory;  ///< overrides output.directory
  int threads = 0;                              ///< 0: OpenMP default
  bool progress = true;                         ///< progress line (only on a terminal, not in CI)
  bool echo = true;                             ///< log lines on stdout
  /// Continue from this folder's checkpoint.bin (or this checkpoint file) instead of starting.
  std::optional<std::string> restart_from;
};

/// SIGINT or SIGTERM stopped the run after it wrote a checkpoint, a final frame and summary.json
/// (status "interrupted"); the command line exits with 128 + signal (130, 143).
class RunInterrupted : public std::runtime_error {
 public:
  RunInterrupted(int signal, const std::string& message)
      : std::runtime_error(message), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// Runs the scene (or continues it from a checkpoint); throws InputError before writing anything
/// for a bad scene or checkpoint, InstabilityError (after writing summary.json with status
/// "unstable") when the run blows up, RunInterrupted on SIGINT/SIGTERM.
void run_scene(const scene::Scene& scene, const RunOptions& options);

/// Validates the scene, builds the simulation and prints the derived quantities.
void check_scene(const scene::Scene& scene, std::ostream& out);

}  // namespace dhpd
