// The time loop of a run (see time_loop.hpp).
#include "tools/run/time_loop.hpp"

#include <fmt/format.h>

#include <csignal>
#include <string>

#include "engine/base/errors.hpp"
#include "refine/event.hpp"
#include "tools/run/hooks.hpp"
#include "tools/run/provenance.hpp"
#include "tools/run/runner.hpp"
#include "tools/run/signals.hpp"

namespace dhpd::run {

namespace {

/// The command that continues this run from its checkpoint (the first command line with its
/// overrides, then -o DIR --restart DIR).
std::string restart_hint(const RunContext& ctx) {
  const auto dir = ctx.checkpoint_file.parent_path().string();
  return ctx.command_words.empty()
             ? fmt::format("dhpd run {} -o {} --restart {}", ctx.scene.file, dir, dir)
             : restart_command(ctx.command_words, dir);
}

/// SIGINT/SIGTERM after step k: the checkpoint of this state (unless step k just wrote it), then
/// a final frame (unless step k wrote one), then RunInterrupted.
[[noreturn]] void interrupt(RunContext& ctx, int signal, std::int64_t k, bool frame_written) {
  if (!ctx.checkpoint_due(k)) ctx.checkpoint();
  if (!frame_written) ctx.write_frame();
  const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
  const auto again = restart_hint(ctx);
  throw RunInterrupted(signal,
                       fmt::format("{} after step {} (t = {:.6g} s); checkpoint {}; "
                                   "continue with: {}",
                                   name, k, ctx.sim.time(), ctx.checkpoint_file.string(), again));
}

/// SIGINT/SIGTERM inside the refinement event after step k: back to the last good state, which
/// becomes the checkpoint (and the final frame when no frame of it exists), then RunInterrupted.
[[noreturn]] void interrupt_event(RunContext& ctx, int signal, std::int64_t k) {
  const char* name = signal == SIGINT ? "SIGINT" : "SIGTERM";
  const std::string kept = ctx.write_last_good();
  if (kept.empty())
    throw RunInterrupted(signal, fmt::format("{} during the refinement event after step {}: the "
                                             "event was abandoned; no state was saved to continue "
                                             "from",
                                             name, k));
  const auto again = restart_hint(ctx);
  throw RunInterrupted(
      signal, fmt::format("{} during the refinement event after step {}: the event was abandoned "
                          "and the run went back to its last good state{}; continue with: {}",
                          name, k, kept, again));
}

/// After a static load step: its relaxation trace, and a line in the log.
void log_load_step(RunContext& ctx) {
  const auto& sim = ctx.sim;
  ctx.relaxation->write(sim);
  const auto& r = sim.last_relaxation();
  ctx.log->line(fmt::format(
      "dhpd: load step {} of {} (load factor {:.6g}): {} iterations in {} relaxation{}, "
      "residual {:.3g} of the load{}{}",
      sim.steps_done(), ctx.state->planned_steps, sim.load_factor(), r.iterations, r.rounds,
      r.rounds == 1 ? "" : "s", r.residual,
      r.broken > 0 ? fmt::format(", {} bonds broke", r.broken) : std::string(),
      r.edits > 0 ? fmt::format(", {} refinement event{}", r.edits, r.edits == 1 ? "" : "s")
                  : std::string()));
}

}  // namespace

void time_loop(RunContext& ctx, io::Progress& progress) {
  auto& sim = ctx.sim;
  auto& schedule = *ctx.schedule;
  auto* hook = ctx.hook;
  const std::int64_t first = sim.steps_done() + 1;
  if (first == 1) {
    ctx.record(true);
    ctx.measure(false);
  }
  const InterruptSignals signals;
  // A signal during an event stops it within a fraction of a second; the run then goes back to
  // its last good state (the event had half edited the discretisation) and stops there. On
  // several ranks the event finishes on every rank alike and the run stops after it.
  const bool alone = sim.force_share() == nullptr;
  if (hook && alone) hook->refiner.set_cancel_check([&signals] { return signals.caught() != 0; });
  const struct Forget {
    RefinementHook* hook;
    ~Forget() {
      if (hook) hook->refiner.set_cancel_check({});
    }
  } forget{hook};
  // A static load step checks the triggers after each of its relaxations, before bonds break:
  // a running crack is refined as it grows.
  // (On several ranks a signal waits for the end of the load step: every rank must check alike.)
  const EditTask refine_in_step =
      hook && sim.is_static()
          ? hook->between_relaxations(sim,
                                      [&signals, alone] { return alone && signals.caught() != 0; })
          : EditTask();
  for (std::int64_t k = first; !schedule.finished(k - 1, sim.time()); ++k) {
    // A step that a history row or frame follows computes its strain energy in its force pass.
    const bool records =
        k % ctx.scene.output.history_every == 0 || schedule.frame_due(k, sim.time() + sim.dt());
    {
      // What the previous step handed over: the step's threads first copy the fields of a frame
      // and the damage of a crack measurement (before they change them); one thread of its force
      // pass encodes the frame (and one of the next step's writes its file) and takes the
      // measurement. A measurement still waiting is taken right after the step, also when the
      // step throws (before anything restores or reads the state).
      const SideTask* frame = ctx.frames.side_task();
      const SideTask* crack = ctx.cracks ? ctx.cracks->side_task() : nullptr;
      const SideTask both = [frame, crack] {
        if (frame) (*frame)();
        if (crack) (*crack)();
      };
      const RangeTask* frame_copy = ctx.frame_before_change();
      const RangeTask* crack_copy = ctx.cracks ? ctx.cracks->before_change() : nullptr;
      const RangeTask copies = [frame_copy, crack_copy](std::int64_t begin, std::int64_t end) {
        if (frame_copy) (*frame_copy)(begin, end);
        if (crack_copy) (*crack_copy)(begin, end);
      };
      const struct AfterStep {
        RunContext& ctx;
        ~AfterStep() {
          ctx.step_done();
          if (ctx.cracks && std::uncaught_exceptions() > 0) ctx.cracks->flush_quietly();
        }
      } after_step{ctx};
      try {
        sim.step({.strain_energy = records,
                  .side_task = frame || crack ? &both : nullptr,
                  .before_change = frame_copy || crack_copy ? &copies : nullptr,
                  .between_relaxations = refine_in_step ? &refine_in_step : nullptr});
      } catch (const refine::EventCancelled&) {
        progress.finish();
        interrupt_event(ctx, signals.caught(), k - 1);
      }
      if (ctx.cracks) ctx.cracks->flush();
    }
    if (ctx.relaxation) log_load_step(ctx);
    // A signal already caught starts no refinement event: the run stops after this step.
    if (hook && !sim.is_static() && hook->refiner.due(k, sim) && !signals.caught()) {
      try {
        sim.announce_edit();  // the other ranks of a distributed run check with it
        const auto ev = hook->refiner.check(sim);
        if (ev.parents > 0) hook->log(sim, ev);
      } catch (const refine::EventCancelled&) {
        progress.finish();
        interrupt_event(ctx, signals.caught(), k);
      }
    }
    const bool frame = schedule.frame(k, sim.time());
    if (frame || k % ctx.scene.output.history_every == 0) ctx.record(frame);
    const bool last = schedule.finished(k, sim.time());
    ctx.measure(last);
    progress.update(k, sim.time(), sim.broken_bonds(), ctx.elapsed());
    if (last) break;
    if (ctx.checkpoint_due(k)) ctx.checkpoint();
    if (const int signal = signals.caught()) {
      progress.finish();
      interrupt(ctx, signal, k, frame);
    }
  }
  progress.finish();
  if (ctx.scene.output.checkpoint_every.value_or(1) == 0) {
    ctx.frames.drain();  // a frame that failed is an IoError of the run
    return;
  }
  ctx.finish_with_checkpoint();
}

}  // namespace dhpd::run
