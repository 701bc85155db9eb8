// `dhpd plot` and `dhpd report`: the checks and the call of tools/plot_run.py.
#include "tools/cli/python_commands.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "engine/base/errors.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPython = "/usr/bin/python3";
constexpr const char* kExpected =
    "expected the output directory of a dhpd run, with history.csv or frames (written by "
    "'dhpd run SCENE -o DIR')";

/// The directory of the running executable, or empty when /proc is not there.
fs::path executable_directory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::vector<std::string> script_arguments(const std::string& script, const std::string& command,
                                          const PlotOptions& options) {
  std::vector<std::string> args{"python3", script, command, options.directory};
  if (command == "plot" && !options.times.empty()) {
    std::string times;
    for (const double t : options.times)
      times += fmt::format("{}{:.17g}", times.empty() ? "" : ",", t);
    args.insert(args.end(), {"--times", times});
  }
  if (command == "plot") args.insert(args.end(), {"--field", options.field});
  return args;
}

}  // namespace

void check_run_directory(const std::string& directory) {
  const fs::path dir(directory);
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{}: no such directory; {}", directory, kExpected));
  // A killed, interrupted or failed run still has pictures to show: a history or a frame is
  // enough (the script says what is missing).
  bool frames = false;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    frames = frames || e.path().extension() == ".vtu";
  if (!fs::is_regular_file(dir / "history.csv") && !frames)
    throw InputError(
        fmt::format("{}: neither history.csv nor a frame (.vtu); {}", directory, kExpected));
}

std::string find_tool_script(const std::string& source_dir, const std::string& file) {
  std::vector<fs::path> candidates{fs::path(source_dir) / "tools" / "python" / file};
  if (const fs::path exe = executable_directory(); !exe.empty()) {
    candidates.push_back(exe.parent_path() / "tools" / "python" / file);
    candidates.push_back(exe / file);
  }
  std::string looked;
  for (const fs::path& c : candidates) {
    if (fs::is_regular_file(c)) return c.string();
    looked += (looked.empty() ? "" : ", ") + c.string();
  }
  throw std::runtime_error(fmt::format("cannot find {} (looked for {})", file, looked));
}

std::string find_plot_script(const std::string& source_dir) {
  return find_tool_script(source_dir, "plot_run.py");
}

namespace {

/// Runs /usr/bin/python3 with `args` (args[0] = "python3"); 0 or 2 from the script are returned
/// (and 1 when `one_means_failed`: a script that reports failed checks), anything else throws.
int run_python(const std::vector<std::string>& args, const std::string& command,
               bool one_means_failed = false) {
  if (access(kPython, X_OK) != 0)
    throw InputError(fmt::format(
        "{} is missing; dhpd {} needs Debian's Python 3 with matplotlib, numpy, scipy, yaml and "
        "VTK 9: sudo apt-get install python3 python3-matplotlib python3-numpy python3-scipy "
        "python3-yaml python3-vtk9",
        kPython, command));
  const std::string& script = args.at(1);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::cout.flush();
  pid_t pid = 0;
  if (const int error = posix_spawn(&pid, kPython, nullptr, nullptr, argv.data(), environ))
    throw std::runtime_error(fmt::format("cannot start {}: {}", kPython, std::strerror(error)));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw std::runtime_error(fmt::format("waiting for {}: {}", script, std::strerror(errno)));
  }
  if (WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 2 ||
                            (one_means_failed && WEXITSTATUS(status) == 1)))
    return WEXITSTATUS(status);
  throw std::runtime_error(
      WIFEXITED(status)
          ? fmt::format("{} {} failed with exit code {}", script, command, WEXITSTATUS(status))
          : fmt::format("{} {} was stopped by signal {}", script, command, WTERMSIG(status)));
}

}  // namespace

int run_plot_script(const std::string& script, const std::string& command,
                    const PlotOptions& options) {
  return run_python(script_arguments(script, command, options), command);
}

namespace {

std::string this_executable() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the dhpd executable (/proc/self/exe)");
  return exe.string();
}

}  // namespace

int run_study_script(const std::string& script, const StudyOptions& options) {
  if (!fs::is_regular_file(options.study_file))
    throw InputError(fmt::format("{}: no such study file (a YAML file: see tools/study.py)",
                                 options.study_file));
  std::vector<std::string> args{"python3", script, options.study_file, "--dhpd", this_executable()};
  if (!options.directory.empty()) args.insert(args.end(), {"--out", options.directory});
  return run_python(args, "study", true);  // 1: a variant missed a criterion
}

int run_stress_script(const std::string& script, const StressOptions& options) {
  std::vector<std::string> args{"python3", script, "--dhpd", this_executable()};
  if (!options.check_directories.empty()) {
    if (options.check_directories.size() > 2)
      throw InputError("--check takes one or two run directories (1-thread run, 2-thread run)");
    for (const std::string& d : options.check_directories) {
      if (!fs::is_directory(d))
        throw InputError(
            fmt::format("--check {}: no such directory (a run's output directory)", d));
    }
    args.emplace_back("--check");
    args.insert(args.end(), options.check_directories.begin(), options.check_directories.end());
    return run_python(args, "stress", true);
  }
  if (!options.suite_file.empty()) {
    if (!fs::is_regular_file(options.suite_file))
      throw InputError(fmt::format("{}: no such suite file (a YAML file: see tools/stress.py)",
                                   options.suite_file));
    args.push_back(options.suite_file);
  }
  if (!options.directory.empty()) args.insert(args.end(), {"--out", options.directory});
  return run_python(args, "stress", true);
}

}  // namespace dhpd
