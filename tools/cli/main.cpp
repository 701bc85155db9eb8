// The dhpd command line: run, check, fields, bench, plot, report, study, stress. The only place
// errors become exit codes: 0 success, 1 internal error, 2 bad input (scene, checkpoint or command
// line), 3 unstable run, 4 stopped at the memory budget, 5 an output could not be written (disk
// full, read-only folder), 130 / 143 interrupted by SIGINT / SIGTERM (after a checkpoint).
#include <fmt/core.h>
#include <omp.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <thread>

#include "engine/base/errors.hpp"
#include "engine/distributed/communicator.hpp"
#include "engine/output_fields.hpp"
#include "tools/bench/bench.hpp"
#include "tools/cli/python_commands.hpp"
#include "tools/cli/version.hpp"
#include "tools/run/runner.hpp"
#include "tools/scene/scene.hpp"

namespace {

std::vector<dhpd::scene::Override> parse_overrides(const std::vector<std::string>& sets) {
  std::vector<dhpd::scene::Override> out;
  for (const auto& s : sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw dhpd::InputError(
          fmt::format("--set {}: expected key.path=value (e.g. --set body.0.spacing=5e-4)", s));
    out.push_back({s.substr(0, eq), s.substr(eq + 1)});
  }
  return out;
}

/// `dhpd fields`: every field a frame can hold, with its unit, when it is written and its meaning.
void print_fields(std::ostream& out) {
  out << fmt::format("{:<22} {:<7} {:<11} {}\n", "field", "unit", "written", "meaning");
  for (const auto& f : dhpd::output_fields())
    out << fmt::format("{:<22} {:<7} {:<11} {}\n", f.name, f.unit,
                       f.always ? "always" : "on request", f.doc);
  out << "Frames' points are the reference positions X (m). Ask for fields written on request in "
         "the scene: output: {fields: [NAME, ...]}.\n";
}

/// Whether this process reports errors: the only process, or rank 0 of an MPI launch (the other
/// ranks meet the same errors at the same point and stay quiet).
bool reports = true;

int report(const char* kind, const std::exception& e, int code) {
  if (reports) std::cerr << "dhpd: " << kind << ": " << e.what() << "\n";
  return code;
}

/// Threads per rank when --threads is not given: the node's cores shared by its ranks.
int threads_per_rank(int threads) {
  if (threads > 0) return threads;
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const int ranks = local ? std::max(1, std::atoi(local)) : 1;
  if (ranks == 1) return 0;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / ranks);
}

}  // namespace

int main(int argc, char** argv) {
  // Line-buffered even when stdout is a file or a pipe: a redirected or killed run keeps its log.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // Under mpirun every rank runs this program (docs/theory.md §25); otherwise MPI is never touched.
  std::optional<dhpd::distributed::MpiSession> mpi;
  if (dhpd::distributed::MpiSession::launched_by_mpirun()) mpi.emplace(argc, argv);
  const auto comm =
      mpi ? dhpd::distributed::Communicator::world() : dhpd::distributed::Communicator::solo();
  reports = comm->root();
  CLI::App app{"dhpd: dual-horizon peridynamics for dynamic fracture"};
  app.require_subcommand(1);
  app.set_version_flag(
      "--version", fmt::format("dhpd {} (commit {})", dhpd::dhpd_version(), dhpd::dhpd_commit()));
  std::string scene_file, out_dir, restart_dir;
  std::vector<std::string> sets;
  int threads = 0;
  bool quiet = false;

  auto* run = app.add_subcommand("run", "run a scene: VTK frames, history.csv, summary.json");
  run->add_option("scene", scene_file, "scene file (YAML)")->required();
  run->add_option("-o,--out", out_dir, "output directory (overrides output.directory)");
  run->add_option("--set", sets, "override a scene key: key.path=value (repeatable)");
  run->add_option("-t,--threads", threads, "OpenMP threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  run->add_flag("-q,--quiet", quiet, "no log lines or progress");
  std::string partition = "rcb";
  run->add_option("--partition", partition,
                  "under mpirun: Zoltan's partitioner, rcb (coordinate bisection) or hsfc "
                  "(Hilbert curve)")
      ->check(CLI::IsMember({"rcb", "hsfc"}));
  std::string repartition = "imbalance";
  run->add_option("--repartition", repartition,
                  "under mpirun: when Zoltan cuts again: imbalance (new particles follow the cuts "
                  "until the largest rank's work exceeds the mean by 10 %), events (after every "
                  "refinement event), steps (before every step: a stress test)")
      ->check(CLI::IsMember({"imbalance", "events", "steps"}));
  bool overwrite = false;
  run->add_flag("--overwrite", overwrite,
                "replace another run's outputs in the output folder (removes exactly the files a "
                "dhpd run writes; without it such a folder is refused)");
  run->add_option(
         "--restart", restart_dir,
         "continue the run whose outputs are in DIR from DIR/checkpoint.bin (or from a checkpoint "
         "file); "
         "give the same scene and --set overrides as the first run")
      ->option_text("DIR");
  run->footer(
      "Checkpoints: OUT/checkpoint.bin at the end of a run and every output.checkpoint_every "
      "steps (the one before stays as checkpoint.prev.bin). SIGINT/SIGTERM finish the step, "
      "write a checkpoint, a final frame and summary.json (status interrupted), then exit 130 / "
      "143. A restarted run's results equal an uninterrupted run's, bit for bit.\n"
      "Example: dhpd run plate.yaml -o out --restart out");

  auto* check = app.add_subcommand(
      "check",
      "validate a scene; print its warnings and what it will cost (particles, bonds, "
      "memory, steps) without building it");
  check->add_option("scene", scene_file, "scene file (YAML)")->required();
  check->add_option("--set", sets, "override a scene key: key.path=value (repeatable)");
  bool build_check = false;
  check->add_flag("--build", build_check,
                  "also build the simulation (every bond) and print its derived values");
  double max_memory_mb = 0;
  for (auto* cmd : {run, check})
    cmd->add_option("--max-memory", max_memory_mb,
                    "memory the run may use, MB (default: the machine's available memory)")
        ->check(CLI::PositiveNumber);

  auto* fields = app.add_subcommand(
      "fields", "the fields a frame can hold: unit, whether always written, meaning");

  dhpd::BenchOptions bench_opt;
  auto* bench = app.add_subcommand(
      "bench",
      "whole-step ns per directed bond per core on the Kalthoff-Winkler plate, beside LAMMPS");
  bench
      ->add_option("--cells", bench_opt.cells,
                   "a cubic lattice of cells^3 particles instead of the plate (100: 1 M)")
      ->check(CLI::Range(4, 400));
  bench->add_option("--steps", bench_opt.steps, "steps per sample (default 100)")
      ->check(CLI::Range(1, 100000));
  bench->add_option("--repeats", bench_opt.repeats, "samples (median reported, default 5)")
      ->check(CLI::Range(1, 100));
  bench->add_option("--threads", bench_opt.threads, "thread counts (LAMMPS: MPI ranks) to compare")
      ->check(CLI::Range(1, 1024));
  bench->add_option("--lammps", bench_opt.lammps,
                    "auto: run LAMMPS (lmp) beside dhpd when installed; off; or the lmp command");
  bench->add_flag("--mpi", bench_opt.mpi,
                  "the plate on R MPI ranks (mpirun) against R threads, R from --threads, with "
                  "the exchange terms of the scale model (docs/verification.md, Distributed runs)");
  bench->add_flag("--refinement", bench_opt.refinement,
                  "time refinement events on the same refined set in bodies of N, 4N, 16N");
  bench->add_flag("--outputs", bench_opt.outputs,
                  "time a scene's outputs and diagnostics: the scene against itself with one "
                  "frame and no history, measurement or checkpoint (--repeats pairs of runs)");
  bench->add_option("--scene", bench_opt.scene,
                    "the scene of --outputs (default cases/branching_plate_uniform.yaml)");

  dhpd::PlotOptions plot_opt;
  auto* plot = app.add_subcommand(
      "plot", "pictures of a run in OUTDIR/plots/: field frames, energies, momentum, dt, cracks");
  plot->add_option("outdir", plot_opt.directory, "output directory of a run")->required();
  plot->add_option("--times", plot_opt.times, "plot the frames nearest these times, s: T1,T2,...")
      ->delimiter(',');
  plot->add_option("--field", plot_opt.field, "frame field to plot (default damage)");
  auto* report_cmd = app.add_subcommand(
      "report", "OUTDIR/report.md: the run, its pictures, measured vs published numbers");
  report_cmd->add_option("outdir", plot_opt.directory, "output directory of a run")->required();
  dhpd::StudyOptions study_opt;
  auto* study = app.add_subcommand(
      "study",
      "what accuracy costs in time: run a study's variants, write study.csv/.md, pareto.png "
      "(exit 1 if a variant misses the study's criteria)");
  study->add_option("study", study_opt.study_file, "study file (YAML, see tools/python/study.py)")
      ->required();
  study->add_option("-o,--out", study_opt.directory, "output folder (default study-NAME)");
  dhpd::StressOptions stress_opt;
  auto* stress = app.add_subcommand(
      "stress",
      "stability suite: run each case with 1 and 2 threads, check NaN/Inf, energy, "
      "momentum, volumes, reproducibility; write stress.csv/.md (exit 1 if any fails)");
  stress->add_option(
      "suite", stress_opt.suite_file,
      "suite file (YAML, see tools/python/stress.py; default cases/stress/suite.yaml)");
  stress->add_option("-o,--out", stress_opt.directory, "output folder (default stress-NAME)");
  stress->add_option("--check", stress_opt.check_directories,
                     "check the outputs of existing runs instead: DIR1 [DIR2 of the 2-thread run]");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "dhpd: error: " << e.what() << "\n"
              << "run 'dhpd --help' for usage\n";
    return 2;
  }

  try {
    if (*study)
      return dhpd::run_study_script(dhpd::find_tool_script(DHPD_SOURCE_DIR, "study.py"), study_opt);
    if (*stress)
      return dhpd::run_stress_script(dhpd::find_tool_script(DHPD_SOURCE_DIR, "stress.py"),
                                     stress_opt);
    if (*plot || *report_cmd) {
      dhpd::check_run_directory(plot_opt.directory);
      return dhpd::run_plot_script(dhpd::find_plot_script(DHPD_SOURCE_DIR),
                                   *plot ? "plot" : "report", plot_opt);
    }
    if (*fields) {
      print_fields(std::cout);
      return 0;
    }
    if (*bench) {
      if (bench_opt.mpi)
        dhpd::run_mpi_bench(bench_opt, std::cout);
      else if (bench_opt.outputs)
        dhpd::run_outputs_bench(bench_opt, std::cout);
      else if (bench_opt.refinement)
        dhpd::run_refinement_bench(bench_opt, std::cout);
      else
        dhpd::run_bench(bench_opt, std::cout);
      return 0;
    }
    const auto scene = dhpd::scene::load_scene(scene_file, parse_overrides(sets));
    if (*check) {
      dhpd::check_scene(scene, std::cout, build_check,
                        max_memory_mb > 0 ? std::optional<double>(max_memory_mb) : std::nullopt);
      return 0;
    }
    dhpd::RunOptions opt;
    if (!out_dir.empty()) opt.output_directory = out_dir;
    opt.threads = threads_per_rank(threads);
    opt.progress = !quiet && comm->root();
    opt.echo = !quiet && comm->root();
    opt.comm = comm;
    opt.partition = partition == "hsfc" ? dhpd::distributed::PartitionMethod::Hsfc
                                        : dhpd::distributed::PartitionMethod::Rcb;
    using dhpd::distributed::RepartitionPolicy;
    opt.repartition = repartition == "events"  ? RepartitionPolicy::Events
                      : repartition == "steps" ? RepartitionPolicy::Steps
                                               : RepartitionPolicy::Imbalance;
    if (!restart_dir.empty()) opt.restart_from = restart_dir;
    opt.overwrite = overwrite;
    if (max_memory_mb > 0) opt.max_memory_mb = max_memory_mb;
    opt.command_words.assign(argv, argv + argc);
    opt.command_words.front() = "dhpd";
    if (comm->root())
      dhpd::run_scene(scene, opt);
    else
      dhpd::serve_scene(scene, opt);
    return 0;
  } catch (const dhpd::InputError& e) {
    return report("error", e, 2);
  } catch (const dhpd::InstabilityError& e) {
    return report("unstable run stopped", e, 3);
  } catch (const dhpd::IoError& e) {
    return report("I/O error", e, 5);
  } catch (const std::filesystem::filesystem_error& e) {
    return report("I/O error", e, 5);
  } catch (const dhpd::ResourceLimit& e) {
    return report("stopped", e, 4);
  } catch (const dhpd::RunInterrupted& e) {
    return report("interrupted", e, 128 + e.signal());
  } catch (const std::exception& e) {
    return report("internal error", e, 1);
  }
}
