// `dhpd bench`: whole-step throughput in ns per directed bond per core (one bond i→j of a full
// neighbour list; an unordered pair is two), with and without fracture, on the Kalthoff–Winkler
// plate of the LAMMPS peri/pmb deck (lammps_deck.cpp), side by side with LAMMPS when `lmp` is
// installed; or on a cubic lattice (--cells), e.g. for memory per particle at 1 M particles.
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

namespace dhpd {

struct BenchOptions {
  int cells = 0;    ///< > 0: a cubic lattice of cells³ particles instead of the plate
  int steps = 100;  ///< steps per timed sample
  int repeats = 5;  ///< samples per configuration; the median is reported
  std::vector<int> threads{1, 2};
  double horizon_factor = 3.015;
  bool refinement = false;      ///< time refinement events instead (bench_refinement.cpp)
  std::string lammps = "auto";  ///< auto (when lmp is on PATH), off, or the lmp command
  bool mpi = false;             ///< R MPI ranks against R threads (bench_mpi.cpp; R from `threads`)
  bool outputs = false;  ///< time a scene's outputs and diagnostics instead (bench_outputs.cpp)
  std::string scene = "cases/branching_plate_uniform.yaml";  ///< the scene of `outputs`
};

/// Runs the benchmark and prints a table (ns per directed bond per core, bytes per particle).
void run_bench(const BenchOptions& options, std::ostream& out);

/// The plate with fracture on R ranks of one thread (mpirun) against one process of R threads,
/// for each R of `threads`: ns per directed bond per core, exchange time and bytes per step,
/// load imbalance, partition time. Under mpirun it is the child that measures.
void run_mpi_bench(const BenchOptions& options, std::ostream& out);

/// Times one refinement event on the same refined set in bodies of N, 4N and 16N particles.
void run_refinement_bench(const BenchOptions& options, std::ostream& out);

/// Times `options.scene` as it is against the same scene with one frame and no history rows,
/// crack measurement or checkpoint: `repeats` pairs of whole `dhpd run` processes (the binary
/// running this), alternating, after a warm-up pair; prints medians and the pairs' ratio.
void run_outputs_bench(const BenchOptions& options, std::ostream& out);

}  // namespace dhpd
