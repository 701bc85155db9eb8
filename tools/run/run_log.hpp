// The log of a run: each line to stdout (unless quiet) and, once the output folder exists, to
// OUT/run.log with a timestamp, flushed at once so a killed run keeps every line it printed.
#pragma once
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace dhpd::run {

class RunLog {
 public:
  explicit RunLog(bool echo) : echo_(echo) {}
  /// Starts (or, restarting, continues) OUT/run.log; lines logged before it are written first.
  void open(const std::string& path, bool append);
  /// One line (no trailing newline).
  void line(std::string_view text);
  bool echo() const { return echo_; }

 private:
  void to_file(std::string_view stamp, std::string_view text);
  bool echo_;
  std::ofstream file_;
  std::vector<std::pair<std::string, std::string>> early_;  ///< (stamp, text) before open()
};

}  // namespace dhpd::run
