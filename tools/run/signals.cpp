// The interrupt flag of a run (the one file-local signal flag the project allows).
#include "tools/run/signals.hpp"

#include <csignal>

namespace dhpd {
namespace {

volatile std::sig_atomic_t caught_signal = 0;

extern "C" void remember_signal(int signal) {
  caught_signal = signal;
}

}  // namespace

struct InterruptSignals::Saved {
  struct sigaction interrupt, terminate;
};

InterruptSignals::InterruptSignals() : saved_(std::make_unique<Saved>()) {
  caught_signal = 0;
  struct sigaction action = {};
  action.sa_handler = remember_signal;
  sigemptyset(&action.sa_mask);
  // Writes in progress complete (the loop checks between steps); a second signal takes the
  // default action at once (every file being written is still a temporary one).
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &action, &saved_->interrupt);
  sigaction(SIGTERM, &action, &saved_->terminate);
}

InterruptSignals::~InterruptSignals() {
  sigaction(SIGINT, &saved_->interrupt, nullptr);
  sigaction(SIGTERM, &saved_->terminate, nullptr);
}

int InterruptSignals::caught() const {
  return caught_signal;
}

}  // namespace dhpd
