// `dhpd bench --mpi` (docs/verification.md, "Distributed runs"; docs/theory.md §25): the
// Kalthoff–Winkler plate with fracture on R MPI ranks of one thread each against one process with
// R threads, in ns per directed bond per core, with the terms the scale model needs.
#include <fmt/core.h>
#include <fmt/ostream.h>
#include <omp.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "engine/distributed/communicator.hpp"
#include "tools/bench/bench.hpp"
#include "tools/bench/bench_plate.hpp"
#include "tools/bench/child_process.hpp"

namespace dhpd {
namespace {
namespace fs = std::filesystem;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// What one configuration measured (per step, rank 0's clock).
struct MpiSample {
  int ranks = 1, threads = 1;
  double step_s = 0, exchange_s = 0, partition_s = 0, imbalance = 1, shared_bytes = 0;
  double force_s = 0;  ///< the force phase per step (the gathers included on several ranks)
  double bonds = 0, particles = 0;
  double ns_per_bond_core() const { return step_s * 1e9 * ranks * threads / bonds; }
};

/// Times the plate on this launch's ranks (every rank calls it; rank 0 gets the sample).
MpiSample time_plate(const BenchOptions& o, std::shared_ptr<const distributed::Communicator> comm) {
  Simulation sim(bench::plate_setup(bench::Plate{}, true));
  MpiSample s;
  s.ranks = comm->size();
  s.threads = omp_get_max_threads();
  s.bonds = static_cast<double>(sim.bonds().bond_count());
  s.particles = static_cast<double>(sim.particles().size());
  sim.distribute(comm, distributed::PartitionMethod::Rcb);
  if (!sim.leads()) {
    sim.serve();
    return s;
  }
  const auto* share = sim.force_share();
  std::vector<double> steps, exchanges, shared, forces;
  for (int r = 0; r < o.repeats; ++r) {
    const double f0 = sim.timers().seconds(Phase::Forces);
    const double ex0 = share ? share->stats().exchange_seconds : 0.0;
    const double v0 = share ? static_cast<double>(share->stats().values_shared) : 0.0;
    const auto t0 = std::chrono::steady_clock::now();
    sim.run_steps(o.steps);
    steps.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                    o.steps);
    exchanges.push_back(((share ? share->stats().exchange_seconds : 0.0) - ex0) / o.steps);
    shared.push_back(((share ? static_cast<double>(share->stats().values_shared) : 0.0) - v0) *
                     8.0 / o.steps);
    forces.push_back((sim.timers().seconds(Phase::Forces) - f0) / o.steps);
  }
  sim.release_ranks();
  s.step_s = median(steps);
  s.exchange_s = median(exchanges);
  s.shared_bytes = median(shared);
  s.force_s = median(forces);
  if (share) {
    s.partition_s = share->stats().partition_seconds;
    s.imbalance = share->stats().imbalance;
  }
  return s;
}

void print_sample(std::ostream& out, const std::string& what, const MpiSample& s) {
  fmt::print(out, "{:<22} {:>6} {:>13.2f} {:>9.2f} {:>12.2f} {:>11.2f} {:>10.3f} {:>9.4f}\n", what,
             s.ranks * s.threads, s.ns_per_bond_core(), s.step_s * 1e3, s.exchange_s * 1e3,
             s.shared_bytes / 1e6, s.imbalance, s.partition_s);
}

/// The terms of the scale model (docs/verification.md, "Distributed runs") from one thread and
/// from the widest launch, and what they predict for a 100 M-particle 3D run.
void print_model(std::ostream& out, const MpiSample& one, const MpiSample& wide) {
  const double c_force = one.force_s / one.bonds;                      // s per directed bond
  const double c_rest = (one.step_s - one.force_s) / one.particles;    // s per particle, every rank
  const double values = wide.shared_bytes / 8.0 / wide.particles;      // values per particle, step
  const double c_value = wide.exchange_s / (wide.shared_bytes / 8.0);  // s per value gathered
  fmt::print(out,
             "\nscale model terms: force pass {:.2f} ns per directed bond; replicated work "
             "{:.1f} ns per particle per rank; {:.1f} values gathered per particle and step, "
             "{:.2f} ns per value on {} ranks here\n",
             c_force * 1e9, c_rest * 1e9, values, c_value * 1e9, wide.ranks);
  const double n = 1e8, bonds = n * one.bonds / one.particles;
  for (const int ranks : {64, 1024}) {
    const double compute = c_force * bonds / ranks, rest = c_rest * n;
    const double exchange = c_value * values * n;
    fmt::print(out,
               "  100 M particles on {} ranks: force pass {:.3f} s + replicated {:.3f} s + "
               "gathers {:.3f} s per step (at this machine's per-value cost)\n",
               ranks, compute, rest, exchange);
  }
}

/// The line a child launch prints for its parent.
std::string result_line(const MpiSample& s) {
  return fmt::format(
      "mpi-bench-result {} {} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n",
      s.ranks, s.threads, s.step_s, s.exchange_s, s.partition_s, s.imbalance, s.shared_bytes,
      s.bonds, s.particles, s.force_s);
}

bool parse_result(const std::string& text, MpiSample& s) {
  const auto at = text.find("mpi-bench-result ");
  if (at == std::string::npos) return false;
  std::istringstream in(text.substr(at + 17));
  return static_cast<bool>(in >> s.ranks >> s.threads >> s.step_s >> s.exchange_s >>
                           s.partition_s >> s.imbalance >> s.shared_bytes >> s.bonds >>
                           s.particles >> s.force_s);
}

/// `mpirun -np RANKS` of this binary in child mode; its sample, or why not.
std::optional<MpiSample> launch(const BenchOptions& o, int ranks, std::string& why) {
  const fs::path log = fs::temp_directory_path() / fmt::format("dhpd_bench_mpi_{}.log", getpid());
  long rss = 0;
  const std::vector<std::string> argv{"mpirun",
                                      "--oversubscribe",
                                      "-np",
                                      std::to_string(ranks),
                                      "-x",
                                      "OMP_NUM_THREADS=1",
                                      fs::canonical("/proc/self/exe").string(),
                                      "bench",
                                      "--mpi",
                                      "--steps",
                                      std::to_string(o.steps),
                                      "--repeats",
                                      std::to_string(o.repeats)};
  const int code = bench::run_child(
      argv, log, rss, {{"OMPI_ALLOW_RUN_AS_ROOT", "1"}, {"OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"}});
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  fs::remove(log);
  MpiSample s;
  if (code == 0 && parse_result(text, s)) return s;
  why = fmt::format("mpirun exited with {}: {}", code, text.substr(0, 400));
  return std::nullopt;
}
}  // namespace

void run_mpi_bench(const BenchOptions& o, std::ostream& out) {
  const bool child = distributed::MpiSession::launched_by_mpirun();
  auto comm = child ? distributed::Communicator::world() : distributed::Communicator::solo();
  if (child) {  // a child launch: measure, print a line
    const auto s = time_plate(o, comm);
    if (comm->root()) out << result_line(s);
    return;
  }
  const bench::Plate plate;
  fmt::print(out,
             "dhpd bench --mpi: Kalthoff-Winkler plate {} x {} x {} sites with fracture; median "
             "of {} samples of {} steps; R ranks of one thread against one process of R threads\n"
             "(ranks above the machine's cores are oversubscribed)\n\n",
             plate.nx, plate.ny, plate.nz, o.repeats, o.steps);
  fmt::print(out, "{:<22} {:>6} {:>13} {:>9} {:>12} {:>11} {:>10} {:>9}\n", "run", "cores",
             "ns/bond/core", "ms/step", "exchange ms", "MB/step", "imbalance", "Zoltan s");
  std::optional<MpiSample> serial;
  std::optional<MpiSample> widest;  // the most ranks with an exchange
  for (const int r : o.threads) {
    omp_set_num_threads(r);
    const auto threads = time_plate(o, comm);
    if (r == 1) serial = threads;
    print_sample(out, fmt::format("1 process, {} thread{}", r, r > 1 ? "s" : ""), threads);
    std::string why;
    if (const auto s = launch(o, r, why)) {
      print_sample(out, fmt::format("{} rank{} x 1 thread", r, r > 1 ? "s" : ""), *s);
      if (s->ranks > 1 && s->shared_bytes > 0) widest = s;
    } else {
      fmt::print(out, "{} ranks not run: {}\n", r, why);
    }
  }
  if (serial && widest) print_model(out, *serial, *widest);
}

}  // namespace dhpd
