// Typed errors thrown at module boundaries; only the command line turns them into exit codes.
#pragma once
#include <stdexcept>
#include <string>

namespace dhpd {

/// A problem with the user's input (scene file, command line): exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// More time levels than the scene allows (time.max_levels): an InputError the scene reader
/// places at that key.
class TimeLevelError : public InputError {
 public:
  using InputError::InputError;
};

/// The multi-horizon model cannot be set up on these particles (no refinement zone, an α
/// undefined): an InputError the scene reader places at the `model` key.
class MultiHorizonError : public InputError {
 public:
  using InputError::InputError;
};

/// The run became unstable (NaN, energy blow-up): exit code 3, last good output kept.
class InstabilityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writing or reading an output failed (disk full, a read-only folder, a path that is a file):
/// exit code 5, with the path and the system's reason; files already written stay valid.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A distributed run's rank 0 stopped what every rank was about to do (a refinement event over
/// the memory budget): the other ranks drop it, unchanged, and wait for rank 0's word.
class StoppedByRankZero : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An internal invariant failed (a bug, not the user's fault): exit code 1.
class EngineError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace dhpd
