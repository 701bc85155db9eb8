// Text outputs of a run: history.csv, refinement.csv, cracks.csv, summary.json and the terminal
// progress line.
#pragma once
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "tools/measure/crack_measure.hpp"

namespace dhpd::io {

/// The length of a CSV file as written so far (every row is flushed).
std::uint64_t bytes_written(std::ofstream& out);
/// A CSV file with its header written and flushed, or opened at its end to continue it; `what`
/// names it in errors (IoError).
std::ofstream open_csv(const std::string& path, const char* header, const char* what, bool append);
/// Appends one row and flushes it, so a crash keeps every row written before.
void write_row(std::ofstream& out, const std::string& row, const char* what);

struct HistoryRow {
  std::int64_t step = 0;
  double time = 0, dt = 0;
  std::int64_t particles = 0, bonds = 0, broken_bonds = 0;
  double kinetic_energy = 0, strain_energy = 0, external_work = 0;
  double momentum[3] = {0, 0, 0};
  /// Particles per time level (docs/theory.md §19), written when the writer has level columns.
  std::vector<std::int64_t> particles_per_level;
  /// The probes' values (probes.hpp), written when the writer has probe columns.
  std::vector<double> probe_values;
};

/// history.csv with a fixed header; every row is flushed so a crash keeps what was written.
class HistoryWriter {
 public:
  /// `append`: continue a file (a restart has cut it back to the checkpoint), no new header.
  /// `level_columns` > 0 (time.multirate: time.max_levels) adds particles_level_0, ... after the
  /// momentum; `probe_columns` (output.probes) come last.
  explicit HistoryWriter(const std::string& path, bool append = false, int level_columns = 0,
                         std::vector<std::string> probe_columns = {});
  void write(const HistoryRow& row);
  std::uint64_t bytes() { return bytes_written(out_); }

 private:
  std::ofstream out_;
  int level_columns_ = 0;
  std::size_t probe_columns_ = 0;
};

/// One row of refinement.csv: what an event did and when.
struct RefinementRow {
  std::int64_t generation = 0, step = 0;
  double time = 0;
  std::int64_t parents = 0, children = 0, dropped = 0, particles = 0, bonds = 0;
  std::int64_t rows_rebuilt = 0, bonds_rebuilt = 0, rows_touched = 0, started_broken = 0;
  std::int64_t started_overstretched = 0, reduced_fits = 0;
  double mapping_energy = 0.0;  ///< kinetic + strain energy the state mapping changed (J)
  double dt = 0, seconds = 0;
  int resorted = 0;
  double resort_seconds = 0;
};

/// refinement.csv with a fixed header, flushed per row.
class RefinementWriter {
 public:
  explicit RefinementWriter(const std::string& path, bool append = false);
  void write(const RefinementRow& row);
  std::uint64_t bytes() { return bytes_written(out_); }

 private:
  std::ofstream out_;
};

/// cracks.csv (`measure`): one row per tip and measurement, header first, flushed per row.
class CrackWriter {
 public:
  CrackWriter(const std::string& path, std::vector<std::string> tip_names, bool append = false);
  void write(const measure::TipRow& row);
  std::uint64_t bytes() { return bytes_written(out_); }

 private:
  std::ofstream out_;
  std::vector<std::string> names_;
};

/// What summary.json says about the cracks of a run with `measure`.
struct CrackReport {
  double rayleigh_speed = 0.0;
  std::vector<measure::CrackSummary> cracks;
  std::optional<measure::Published> published;
};

struct PhaseSeconds {
  std::string name;
  double seconds = 0;
};

/// The particles of one material at the end of a run and the bonds they own (a bond uses its
/// owner's material, CMAME 2017 §5.2).
struct MaterialCount {
  std::string name;
  std::int64_t particles = 0, bonds = 0, broken_bonds = 0;
  std::int64_t damaged_particles = 0;  ///< particles with at least one broken bond of their own
};

struct Summary {
  std::string scene_name, scene_file, status = "completed", message;
  double wall_seconds = 0;
  std::int64_t steps = 0, particles_start = 0, particles_end = 0, bonds = 0, broken_bonds = 0;
  std::int64_t refinement_events = 0;
  double end_time = 0, dt = 0, critical_dt = 0;
  double bond_updates_per_second = 0, particle_steps_per_second = 0;
  int threads = 1;
  /// MPI ranks of the run (docs/theory.md §25), the partitioner and its load imbalance (largest
  /// rank's bond entries over the mean), and the values the ranks shared (8 or 1 bytes each).
  int ranks = 1;
  std::string partitioner;
  double imbalance = 1.0;
  std::int64_t values_shared = 0;
  std::int64_t repartitions = 0, moved = 0;  ///< Zoltan cuts; particles that changed owner
  /// Provenance: dhpd's version, the source tree's commit, the command line that ran.
  std::string version, commit, command_line;
  double peak_memory_mb = 0;  ///< this process's own peak resident memory (VmHWM)
  /// The simulation's arrays at the end (capacities): total and by part, in bytes.
  struct Allocated {
    std::int64_t total = 0, particles = 0, bonds = 0, other = 0;
  } allocated;
  std::vector<std::string> warnings;  ///< legal but probably unintended settings (log lines too)
  std::vector<std::string> active_effects;
  std::vector<PhaseSeconds> phases;
  std::vector<MaterialCount> materials;
  std::optional<CrackReport> cracks;  ///< with `measure` only
  /// With time.multirate: particles per level at the end, directed bonds evaluated per level and
  /// by one global step at the finest level instead (this process's steps).
  struct TimeLevels {
    std::vector<std::int64_t> particles, evaluated;
    std::int64_t one_step = 0;
  };
  std::optional<TimeLevels> time_levels;
};

/// Writes summary.json (atomically: temporary file, then rename).
void write_summary(const std::string& path, const Summary& s);
/// Writes `text` to `path` via a temporary file in the same directory and a rename.
void write_text_atomically(const std::string& path, const std::string& text);

/// One-line progress on a terminal: step, time, ETA, broken bonds. Silent when stderr is not a
/// terminal or the CI environment variable is set. A run that ends at a time (`end_time`) counts
/// its progress in simulated time, since refinement changes the step: the ETA is the time left
/// at the rate of the last few seconds of wall time, not a step count fixed at the start.
class Progress {
 public:
  /// `first_step`: the steps done before this process (a restart); the ETA uses only the rest.
  Progress(std::int64_t total_steps, bool enabled, std::int64_t first_step = 0,
           std::optional<double> end_time = std::nullopt);
  void update(std::int64_t step, double time, std::int64_t broken_bonds, double elapsed_seconds);
  void finish();
  static bool wanted();  ///< stderr is a terminal and CI is unset
  /// The ETA text for a run at (step, time) after `elapsed` s (what update prints; "--" unknown).
  std::string eta(std::int64_t step, double time, double elapsed_seconds);

 private:
  std::int64_t total_;
  bool enabled_;
  std::int64_t first_;
  std::optional<double> end_time_;
  double last_print_ = -1.0;
  double rate_time_ = -1.0, rate_wall_ = 0.0;  ///< where the rate window started
  double rate_ = 0.0;                          ///< simulated seconds per wall second
};

}  // namespace dhpd::io
