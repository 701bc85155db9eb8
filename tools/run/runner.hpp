// A whole run of a scene: validation first, then outputs (resolved scene, frames, history,
// summary). Nothing is written before the scene and the simulation have been fully checked.
#pragma once
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/distributed/communicator.hpp"
#include "engine/distributed/partition.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {

struct RunOptions {
  std::optional<std::string> output_directory;  ///< overrides output.directory
  int threads = 0;                              ///< 0: OpenMP default
  bool progress = true;                         ///< progress line (only on a terminal, not in CI)
  bool echo = true;                             ///< log lines on stdout
  /// Continue from this folder's checkpoint.bin (or this checkpoint file) instead of starting.
  std::optional<std::string> restart_from;
  /// Replace another run's outputs in the output folder (else such a folder is refused).
  bool overwrite = false;
  /// The memory the run may use, MB (default: the machine's available memory).
  std::optional<double> max_memory_mb;
  /// The command line's words as typed (summary.json records them; the restart hint reuses them).
  std::vector<std::string> command_words;
  /// The ranks of an MPI launch (docs/theory.md §25); null or one rank: a run in this process.
  std::shared_ptr<const distributed::Communicator> comm;
  distributed::PartitionMethod partition = distributed::PartitionMethod::Rcb;
  distributed::RepartitionPolicy repartition = distributed::RepartitionPolicy::Imbalance;
};

/// A refinement event would have taken the run past its memory budget: the run stopped before
/// it, with its last good state written (summary.json status "resource_limit"; exit 4).
class ResourceLimit : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
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
/// On several ranks this is rank 0's part: it writes every output; the others run serve_scene.
void run_scene(const scene::Scene& scene, const RunOptions& options);

/// Ranks other than 0 of a distributed run: the same checks as run_scene in the same order (so a
/// bad scene, folder or checkpoint stops every rank at the same point, reported by rank 0 alone),
/// the same simulation, then what rank 0 announces until it is done. Writes nothing.
void serve_scene(const scene::Scene& scene, const RunOptions& options);

/// `dhpd check`: the scene is valid; the resource estimate (well under a second, no bond built);
/// then, when `build` is asked or the scene is small (at most 1e6 bonds), the simulation is built,
/// checked as `run` would check it, and its warnings and derived values printed.
void check_scene(const scene::Scene& scene, std::ostream& out, bool build,
                 std::optional<double> max_memory_mb);

}  // namespace dhpd
