// `dhpd bench --outputs`: what a scene's outputs and diagnostics cost in wall time. The scene runs
// as it is and with one frame, no history rows, no crack measurement and no checkpoint, each run
// a whole `dhpd run` process, the two alternating, so a drift of the machine's speed hits both.
// Each run writes into an empty folder: removing the previous run's files is not timed.
#include <fmt/ostream.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/bench/bench.hpp"
#include "tools/bench/child_process.hpp"
#include "tools/scene/scene.hpp"

namespace dhpd {
namespace {

namespace fs = std::filesystem;

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// Wall seconds of one `dhpd run` of the scene into `dir` (emptied first, untimed) with the
/// `--set` overrides.
double timed_run(const std::string& scene, const fs::path& dir,
                 const std::vector<std::string>& sets) {
  fs::remove_all(dir);
  std::vector<std::string> argv = {
      fs::canonical("/proc/self/exe").string(), "run", scene, "-q", "-o", dir.string()};
  for (const auto& s : sets) argv.push_back("--set"), argv.push_back(s);
  long peak = 0;
  const auto log = dir.string() + ".log";
  const auto start = std::chrono::steady_clock::now();
  const int status = bench::run_child(argv, log, peak);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (status != 0)
    throw std::runtime_error(
        fmt::format("dhpd bench --outputs: the run into {} failed (exit {}); "
                    "its messages are in {}",
                    dir.string(), status, log));
  return seconds;
}

void print_times(std::ostream& out, const char* what, const std::vector<double>& t) {
  fmt::print(out, "{:<46} {:>8.3f} {:>8.3f} {:>8.3f}\n", what, median_of(t),
             *std::min_element(t.begin(), t.end()), *std::max_element(t.begin(), t.end()));
}

}  // namespace

void run_outputs_bench(const BenchOptions& o, std::ostream& out) {
  const auto scene = scene::load_scene(o.scene, {});  // bad input is refused before any run
  std::vector<std::string> bare = {"output.frames=1", "output.history_every=1000000000",
                                   "output.checkpoint_every=0"};
  if (scene.measure) bare.push_back("measure.every=1000000000");
  const fs::path dir = fs::temp_directory_path() / fmt::format("dhpd_bench_outputs_{}", getpid());
  fs::create_directories(dir);
  std::vector<double> full, stripped, ratio;
  try {
    for (int r = -1; r < o.repeats; ++r) {  // r = −1: a warm-up pair, not counted
      const double b = timed_run(o.scene, dir / "without", bare);
      const double a = timed_run(o.scene, dir / "with", {});
      if (r < 0) continue;
      full.push_back(a), stripped.push_back(b), ratio.push_back(a / b);
    }
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  fmt::print(out,
             "dhpd bench --outputs: {}, {} pairs of whole `dhpd run` processes (after a warm-up "
             "pair), each into an empty folder, wall seconds\n\n{:<46} {:>8} {:>8} {:>8}\n",
             o.scene, o.repeats, "run", "median", "min", "max");
  print_times(out, "as the scene is", full);
  print_times(out, "one frame; no history, measurement, checkpoint", stripped);
  const double m = median_of(ratio);
  fmt::print(out, "{:<46} {:>8.3f} {:>8.3f} {:>8.3f}\n", "ratio, pair by pair", m,
             *std::min_element(ratio.begin(), ratio.end()),
             *std::max_element(ratio.begin(), ratio.end()));
  fmt::print(out, "outputs and diagnostics: {:.1f} % of the run's wall time (median ratio)\n",
             100.0 * (1.0 - 1.0 / m));
}

}  // namespace dhpd
