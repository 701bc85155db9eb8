// Provenance of a run: the command line, the peak memory, the restart command.
#include "tools/run/provenance.hpp"

#include <fstream>
#include <sstream>

namespace dhpd::run {

namespace {
std::string quoted(const std::string& w) {
  const bool plain = !w.empty() && w.find_first_not_of(
                                       "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOP"
                                       "QRSTUVWXYZ0123456789-_./=:,+@%") == std::string::npos;
  if (plain) return w;
  std::string out = "'";
  for (const char c : w) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}
}  // namespace

std::string shell_command(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : " ") + quoted(w);
  return out;
}

namespace {
/// A "Key:  N kB" line of /proc/self/status, in MB (0 when absent).
double status_mb(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(key, 0) == 0) {
      std::istringstream in(line.substr(key.size()));
      double kb = 0;
      in >> kb;
      return kb / 1024.0;
    }
  return 0.0;
}
}  // namespace

double peak_memory_mb() {
  return status_mb("VmHWM:");
}

double current_memory_mb() {
  return status_mb("VmRSS:");
}

std::string restart_command(const std::vector<std::string>& words, const std::string& dir) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < words.size(); ++k) {
    const std::string& w = words[k];
    const bool takes_value = w == "-o" || w == "--out" || w == "--restart";
    if (takes_value) {
      ++k;  // drop the option and its value
      continue;
    }
    if (w.rfind("--out=", 0) == 0 || w.rfind("--restart=", 0) == 0) continue;
    out.push_back(w);
  }
  out.insert(out.end(), {"-o", dir, "--restart", dir});
  return shell_command(out);
}

}  // namespace dhpd::run
