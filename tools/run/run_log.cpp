// A run's log lines on stdout and in OUT/run.log.
#include "tools/run/run_log.hpp"

#include <fmt/chrono.h>
#include <fmt/core.h>
#include <chrono>
#include <cstdio>

namespace dhpd::run {

namespace {
std::string now_stamp() {
  const auto now = std::chrono::system_clock::now();
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  return fmt::format("{:%Y-%m-%d %H:%M:%S}.{:03d}",
                     fmt::gmtime(std::chrono::system_clock::to_time_t(now)), ms);
}
}  // namespace

void RunLog::open(const std::string& path, bool append) {
  file_.open(path, append ? std::ios::app : std::ios::trunc);
  for (const auto& [stamp, text] : early_) to_file(stamp, text);
  early_.clear();
}

void RunLog::line(std::string_view text) {
  if (echo_) {
    fmt::print("{}\n", text);
    std::fflush(stdout);
  }
  const auto stamp = now_stamp();
  if (file_.is_open())
    to_file(stamp, text);
  else
    early_.emplace_back(stamp, std::string(text));
}

void RunLog::to_file(std::string_view stamp, std::string_view text) {
  file_ << stamp << " UTC  " << text << "\n";
  file_.flush();
}

}  // namespace dhpd::run
