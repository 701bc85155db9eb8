// Parts of the run loop (tools/runner.cpp): the frame schedule, the refinement and crack hooks
// with their CSV logs, and the log lines of a run.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/refiner.hpp"
#include "tools/measure/crack_measure.hpp"
#include "tools/output/text_outputs.hpp"
#include "tools/run/run_log.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd::run {

/// Steps at which frames are written after frame 0: every N steps, or F frames spread evenly.
std::vector<std::int64_t> frame_steps(const scene::Scene& s, std::int64_t total);

/// When a run ends and frames are due. A run with refinement and `time.end` runs to the end time
/// (dt changes at events), with `output.frames` spread over time; otherwise steps are planned.
class Schedule {
 public:
  Schedule(const scene::Scene& s, std::int64_t planned, bool by_time)
      : s_(s), planned_(planned), by_time_(by_time) {
    if (!by_time_) {
      steps_ = frame_steps(s, planned);
    } else if (!s.output.every) {
      const std::int64_t frames = s.output.frames.value_or(20);
      for (std::int64_t k = 1; k < frames; ++k)
        times_.push_back(*s.time.end * static_cast<double>(k) / static_cast<double>(frames));
    }
  }
  bool finished(std::int64_t k, double t) const {
    return by_time_ ? t >= *s_.time.end * (1.0 - 1e-12) : k >= planned_;
  }
  /// Whether frame(k, t) would say yes, without moving on (a forecast before step k).
  bool frame_due(std::int64_t k, double t) const {
    if (finished(k, t)) return true;
    if (!by_time_) return next_ < steps_.size() && steps_[next_] == k;
    if (s_.output.every) return k % *s_.output.every == 0;
    return next_ < times_.size() && t >= times_[next_] * (1.0 - 1e-12);
  }
  /// Whether step k (just done, at time t) writes a frame; call once per step.
  bool frame(std::int64_t k, double t) {
    if (finished(k, t)) return true;
    if (!by_time_) {
      const bool due = next_ < steps_.size() && steps_[next_] == k;
      next_ += due ? 1 : 0;
      return due;
    }
    if (s_.output.every) return k % *s_.output.every == 0;
    bool due = false;
    while (next_ < times_.size() && t >= times_[next_] * (1.0 - 1e-12)) due = true, ++next_;
    return due;
  }
  /// How many planned frame steps or times are behind (checkpoints), and back to that.
  std::uint64_t position() const { return next_; }
  void resume(std::uint64_t position) {
    next_ = std::min<std::size_t>(position, std::max(steps_.size(), times_.size()));
  }

 private:
  const scene::Scene& s_;
  std::int64_t planned_;
  bool by_time_;
  std::vector<std::int64_t> steps_;
  std::vector<double> times_;
  std::size_t next_ = 0;
};

/// The refiner of a scene with effects.refinement and its log (refinement.csv).
struct RefinementHook {
  RefinementHook(const refine::Settings& settings, RunLog& run_log)
      : refiner(settings), log_lines(run_log) {}
  refine::Refiner refiner;
  std::vector<refine::RefinementEvent> pending;  ///< zone events applied before the output existed
  std::unique_ptr<io::RefinementWriter> csv;
  RunLog& log_lines;
  std::int64_t events = 0;

  /// One row of refinement.csv (and a log line) for an event.
  void log(const Simulation& sim, const refine::RefinementEvent& ev);
  /// What a static load step calls after each relaxation (StepExtras::between_relaxations;
  /// docs/theory.md §22, refinement between relaxations): a check of the triggers, logged, and
  /// whether it edited; nothing once `stop` says the run is stopping.
  EditTask between_relaxations(Simulation& sim, std::function<bool()> stop);
};

/// Crack measurements of a scene with `measure`: cracks.csv and the summary's "cracks".
struct CrackHook {
  /// `append`: cracks.csv continues (a restart); `tracker` holds the measurements so far.
  CrackHook(const scene::MeasureSpec& spec, measure::CrackTracker measured,
            const std::filesystem::path& dir, bool append, double c_r)
      : tracker(std::move(measured)),
        csv((dir / "cracks.csv").string(), tip_names(spec.settings), append),
        published(spec.published),
        rayleigh_speed(c_r) {}
  CrackHook(const CrackHook&) = delete;  // side_task() points into it
  CrackHook& operator=(const CrackHook&) = delete;
  measure::CrackTracker tracker;
  io::CrackWriter csv;
  std::optional<measure::Published> published;
  double rayleigh_speed;

  static std::vector<std::string> tip_names(const measure::Settings& s) {
    std::vector<std::string> names;
    for (const auto& t : s.tips) names.push_back(t.name);
    return names;
  }
  void take_measurement(Simulation& sim) {
    auto t = sim.timers().scope(Phase::Diagnostics);
    write_rows(sim.particles(), sim.steps_done(), sim.time(),
               {sim.generation(), sim.layout_version()}, nullptr);
  }

  /// The measurement of the current state, taken later by side_task() (one thread of the next
  /// step's force pass) or flush(). The damage, the one field a step changes that it reads, is
  /// copied by the next step's threads before they change it (before_change()); the particles'
  /// other fields stay those of this state until the next edit, and the run calls flush() after
  /// every step, before anything edits or reads the measurements.
  void defer_measurement(const Simulation& sim) {
    flush();
    const auto& p = sim.particles();
    damage_copy.resize(p.size());
    copied.store(0, std::memory_order_relaxed);
    deferred = Deferred{&p, sim.steps_done(), sim.time(), {sim.generation(), sim.layout_version()}};
  }
  /// The copy of the damage for the next step's threads (StepExtras::before_change; nullptr when
  /// no measurement is waiting).
  const RangeTask* before_change() const { return deferred ? &copy_task : nullptr; }
  /// The deferred measurement's work, for the next force pass (nullptr when none is waiting).
  const SideTask* side_task() const { return deferred ? &task : nullptr; }
  io::CrackReport report() const { return {rayleigh_speed, tracker.summary(), published}; }
  /// Takes a deferred measurement now (if the force pass did not) and throws its error.
  void flush() {
    run_deferred();
    if (error) std::rethrow_exception(std::exchange(error, nullptr));
  }
  /// flush() that keeps the error (a run already stopping for another reason).
  void flush_quietly() noexcept { run_deferred(); }

 private:
  struct Deferred {
    const ParticleStore* particles;
    std::int64_t step;
    double time;
    measure::Revision revision;
  };
  /// Measures (with `damage` instead of p.damage when given) and appends the rows to cracks.csv.
  void write_rows(const ParticleStore& p, std::int64_t step, double time,
                  const measure::Revision& revision, const double* damage) {
    for (const auto& row : tracker.measure(p, step, time, revision, damage)) csv.write(row);
  }
  void run_deferred() noexcept {
    if (!deferred) return;
    const Deferred d = *deferred;
    deferred.reset();
    // Without a whole copy no step got as far as changing the damage: it is still this state's.
    const bool whole =
        copied.load(std::memory_order_relaxed) == static_cast<std::int64_t>(damage_copy.size());
    try {
      write_rows(*d.particles, d.step, d.time, d.revision,
                 whole ? damage_copy.data() : d.particles->damage.data());
    } catch (...) {
      error = std::current_exception();
    }
  }
  std::vector<double> damage_copy;
  std::atomic<std::int64_t> copied{0};  ///< particles of damage_copy written
  std::optional<Deferred> deferred;
  std::exception_ptr error;
  SideTask task{[this] { run_deferred(); }};
  RangeTask copy_task{[this](std::int64_t begin, std::int64_t end) {
    const double* from = deferred->particles->damage.data();
    std::copy(from + begin, from + end, damage_copy.begin() + begin);
    copied.fetch_add(end - begin, std::memory_order_relaxed);
  }};
};

/// Per material of the scene: its particles, the bonds they own and how many of those are broken.
std::vector<io::MaterialCount> material_counts(const scene::Scene& s, const Simulation& sim);

void log_start(RunLog& log, const scene::Scene& s, const Simulation& sim, std::int64_t steps,
               const std::filesystem::path& dir);
void log_end(RunLog& log, const io::Summary& sum);

}  // namespace dhpd::run
