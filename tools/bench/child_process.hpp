// Child processes of `dhpd bench`: LAMMPS beside dhpd, and dhpd itself for --outputs.
#pragma once
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace dhpd::bench {

/// Runs argv (argv[0] found on PATH) with stdout and stderr into `log` and the variables `env`
/// set on top of ours; returns the exit status (−1: not started or killed) and the children's
/// peak resident set size.
int run_child(const std::vector<std::string>& argv, const std::filesystem::path& log,
              long& peak_rss_bytes,
              const std::vector<std::pair<std::string, std::string>>& env = {});

}  // namespace dhpd::bench
