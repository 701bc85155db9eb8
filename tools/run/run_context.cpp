// The end of a run loop: the last frame and the final checkpoint (see run_context.hpp).
#include "tools/run/run_context.hpp"

#include <omp.h>

#include <exception>

#include "engine/base/errors.hpp"

namespace dhpd::run {

void RunContext::finish_with_checkpoint() {
  sim.share_bond_states();  // rank 0 of a distributed run saves every row's bonds
  auto listed = frames.entries_once_written();
  if (!listed || omp_get_max_threads() < 2) {
    frames.drain();  // a frame that failed is an IoError of the run, not of the checkpoint
    try {            // the run is complete: a checkpoint that cannot be written does not undo it
      checkpoint();
    } catch (const IoError& e) {
      warn_unsaved(e);
    }
    return;
  }
  auto& st = *state;
  st = run_state(true, std::move(listed));
  auto t = sim.timers().scope(Phase::Output);
  const auto begin = std::chrono::steady_clock::now();
  std::exception_ptr frame_error, checkpoint_error;
  std::optional<StagedCheckpoint> staged;
  // Two threads, each with its own file; neither changes the simulation or the run's state.
#pragma omp parallel sections num_threads(2)
  {
#pragma omp section
    try {
      frames.drain();
    } catch (...) {
      frame_error = std::current_exception();
    }
#pragma omp section
    try {
      staged.emplace(stage_checkpoint(checkpoint_file.string(), sim, st, scene_text));
    } catch (...) {
      checkpoint_error = std::current_exception();
    }
  }
  if (frame_error) std::rethrow_exception(frame_error);  // the staged file is removed
  try {
    if (checkpoint_error) std::rethrow_exception(checkpoint_error);
    log_checkpoint(staged->commit(), begin);
  } catch (const IoError& e) {
    warn_unsaved(e);
  }
}

void RunContext::warn_unsaved(const IoError& e) {
  unsaved = std::string("the final checkpoint was not written: ") + e.what();
  log->line("dhpd: warning: " + unsaved);
}

}  // namespace dhpd::run
