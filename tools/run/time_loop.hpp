// The time loop of a run (tools/run/runner.cpp sets it up): steps, refinement checks, records,
// crack measurements, checkpoints, and the stops a signal asks for.
#pragma once

#include "tools/output/text_outputs.hpp"
#include "tools/run/run_context.hpp"

namespace dhpd::run {

/// Steps until the schedule says the run is over; refinement checks after each due step, crack
/// measurements at step 0, every `measure.every` steps and at the last step; checkpoints every
/// output.checkpoint_every steps and at the end. A restarted run starts after its checkpoint.
/// SIGINT/SIGTERM end it with RunInterrupted after a checkpoint (or the last good state).
void time_loop(RunContext& ctx, io::Progress& progress);

}  // namespace dhpd::run
