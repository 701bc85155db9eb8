// `dhpd bench`: force-kernel and whole-step throughput on a uniform 3D lattice.
#pragma once
#include <iosfwd>
#include <vector>

namespace dhpd {

struct BenchOptions {
  int cells = 60;   ///< lattice cells per side (60³ = 216,000 particles)
  int steps = 10;   ///< steps per timed sample
  int repeats = 5;  ///< samples per configuration; the median is reported
  std::vector<int> threads{1, 2};
  double horizon_factor = 3.015;
  bool refinement = false;  ///< time refinement events instead (bench_refinement.cpp)
};

/// Runs the benchmark and prints a table (ns per interaction, particle-steps/s, ratios).
void run_bench(const BenchOptions& options, std::ostream& out);

/// Times one refinement event on the same refined set in bodies of N, 4N and 16N particles.
void run_refinement_bench(const BenchOptions& options, std::ostream& out);

}  // namespace dhpd
