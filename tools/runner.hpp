// A whole run of a scene: validation first, then outputs (resolved scene, frames, history,
// summary). Nothing is written before the scene and the simulation have been fully checked.
#pragma once
#include <optional>
#include <string>

#include "tools/scene.hpp"

namespace dhpd {

struct RunOptions {
  std::optional<std::string> output_directory;  ///< overrides output.directory
  int threads = 0;                              ///< 0: OpenMP default
  bool progress = true;                         ///< progress line (only on a terminal, not in CI)
  bool echo = true;                             ///< log lines on stdout
};

/// Runs the scene; throws InputError before writing anything for a bad scene, and
/// InstabilityError (after writing summary.json with status "unstable") when the run blows up.
void run_scene(const scene::Scene& scene, const RunOptions& options);

/// Validates the scene, builds the simulation and prints the derived quantities.
void check_scene(const scene::Scene& scene, std::ostream& out);

}  // namespace dhpd
