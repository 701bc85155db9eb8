// `dhpd plot` and `dhpd report`: check a run directory, find tools/plot_run.py and run it with
// Debian's /usr/bin/python3 (matplotlib, numpy and VTK 9 from python3-matplotlib, python3-numpy,
// python3-vtk9).
#pragma once
#include <string>
#include <vector>

namespace dhpd {

struct PlotOptions {
  std::string directory;      ///< a run's output directory
  std::vector<double> times;  ///< frames nearest these times, s; empty: 4 spread over the run
  std::string field = "damage";
};

/// Throws InputError naming the path and what is expected unless `directory` is a directory
/// holding summary.json and history.csv.
void check_run_directory(const std::string& directory);

/// tools/plot_run.py under `source_dir` (the tree the binary was built from), else beside the
/// executable (EXE_DIR/../tools/ or EXE_DIR/, for a moved tree); throws std::runtime_error
/// naming every place it looked.
std::string find_plot_script(const std::string& source_dir);

/// Runs `/usr/bin/python3 SCRIPT COMMAND DIR [--times T,...] [--field F]` (COMMAND: plot or
/// report) and returns dhpd's exit code: 0 done, 2 when the script reports bad input or a missing
/// Python module (it prints the message). /usr/bin/python3 missing: InputError; the script failing
/// otherwise: std::runtime_error.
int run_plot_script(const std::string& script, const std::string& command,
                    const PlotOptions& options);

}  // namespace dhpd
