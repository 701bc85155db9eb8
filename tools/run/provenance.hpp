// Where a run's numbers come from: the command line as it can be typed again, the process's own
// peak memory, and the exact command that continues an interrupted run.
#pragma once
#include <string>
#include <vector>

namespace dhpd::run {

/// The words joined as a POSIX shell reads them back (single quotes where needed).
std::string shell_command(const std::vector<std::string>& words);

/// This process's peak resident memory so far (VmHWM of /proc/self/status), MB; 0 if unknown.
double peak_memory_mb();
/// This process's resident memory now (VmRSS), MB; 0 if unknown.
double current_memory_mb();

/// The command that continues a run: the original command line with any -o/--out and --restart
/// replaced by `-o DIR --restart DIR` (every --set override kept, as it must be).
std::string restart_command(const std::vector<std::string>& words, const std::string& dir);

}  // namespace dhpd::run
