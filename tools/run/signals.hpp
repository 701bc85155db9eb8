// SIGINT and SIGTERM during a run: the handler only sets a flag; the run loop finishes its step,
// writes a checkpoint, a final frame and summary.json, then exits 130 (SIGINT) or 143 (SIGTERM).
// A second signal stops the process at once.
#pragma once
#include <memory>

namespace dhpd {

/// Catches SIGINT and SIGTERM while alive and restores the previous handlers when destroyed.
class InterruptSignals {
 public:
  InterruptSignals();
  ~InterruptSignals();
  InterruptSignals(const InterruptSignals&) = delete;
  InterruptSignals& operator=(const InterruptSignals&) = delete;
  /// The signal caught since construction, 0 when none.
  int caught() const;

 private:
  struct Saved;
  std::unique_ptr<Saved> saved_;
};

}  // namespace dhpd
