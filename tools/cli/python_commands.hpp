// `dhpd plot`, `dhpd report`, `dhpd study` and `dhpd stress`: check their input, find the Python
// script in tools/ (plot_run.py, study.py, stress.py) and run it with Debian's /usr/bin/python3
// (matplotlib, numpy, scipy, yaml and VTK 9 from python3-matplotlib, python3-numpy, python3-scipy,
// python3-yaml, python3-vtk9).
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

/// tools/`file` under `source_dir` (the tree the binary was built from), else beside the
/// executable (EXE_DIR/../tools/ or EXE_DIR/, for a moved tree); throws std::runtime_error
/// naming every place it looked.
std::string find_tool_script(const std::string& source_dir, const std::string& file);
std::string find_plot_script(const std::string& source_dir);

struct StudyOptions {
  std::string study_file;  ///< the study's YAML file
  std::string directory;   ///< output folder; empty: study-NAME
};

/// Runs `/usr/bin/python3 SCRIPT STUDY --dhpd THIS_EXECUTABLE [--out DIR]` (tools/study.py) with
/// the exit-code conventions of run_plot_script. Throws InputError when the study file is missing.
int run_study_script(const std::string& script, const StudyOptions& options);

struct StressOptions {
  std::string suite_file;                      ///< empty: cases/stress/suite.yaml
  std::string directory;                       ///< output folder; empty: stress-NAME
  std::vector<std::string> check_directories;  ///< --check: outputs to check instead of running
};

/// Runs `/usr/bin/python3 SCRIPT --dhpd THIS_EXECUTABLE [SUITE] [--out DIR]` or, with
/// check_directories, `... --check DIR1 [DIR2]` (tools/stress.py) and returns 0 (every criterion
/// passes), 1 (some fail) or 2 (bad input). Throws InputError for a missing suite file or
/// directory, or more than two directories to check.
int run_stress_script(const std::string& script, const StressOptions& options);

/// Runs `/usr/bin/python3 SCRIPT COMMAND DIR [--times T,...] [--field F]` (COMMAND: plot or
/// report) and returns dhpd's exit code: 0 done, 2 when the script reports bad input or a missing
/// Python module (it prints the message). /usr/bin/python3 missing: InputError; the script failing
/// otherwise: std::runtime_error.
int run_plot_script(const std::string& script, const std::string& command,
                    const PlotOptions& options);

}  // namespace dhpd
