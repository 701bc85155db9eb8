// The LAMMPS side of `dhpd bench`: our own input deck of the Kalthoff–Winkler-like plate for
// LAMMPS's bond-based peri/pmb pair style (the same lattice, horizon, material and impact as the
// dhpd plate), run as a child process and read back.
#pragma once
#include <optional>
#include <string>

namespace dhpd::bench {

/// The plate both engines run: a simple cubic lattice of nx × ny × nz sites of spacing dx (sites
/// at (i + ½) dx), two notches of 4 layers (|y − y_n| < 2 dx, x < nx/4 dx) at y_n = ny/4, 3ny/4,
/// and the first 3 layers at x = 0 between the notches starting at 22 m/s. Steel-like: E = 190
/// GPa, ρ = 7800 kg/m³, G0 = 6.9e4 J/m², δ = 3.015 dx.
struct Plate {
  double dx = 1.5625e-3;
  int nx = 128, ny = 64, nz = 4;
  double E = 190e9, rho = 7800.0, G0 = 6.9e4, impact_speed = 22.0;
  double horizon_factor = 3.015;
  /// Whether lattice site (i, j) lies in a notch.
  bool in_notch(int i, int j) const;
};

struct LammpsRun {
  double loop_seconds = 0;  ///< "Loop time" of the run
  double pair_seconds = 0;  ///< the Pair row of the timing breakdown
  long atoms = 0;
  long peak_rss_bytes = 0;  ///< of the lmp processes (largest rank × ranks)
};

/// The deck text for `steps` steps of the plate (fracture on: peri/pmb always breaks bonds).
std::string lammps_deck(const Plate& plate, int steps);

/// Runs `command` (e.g. "lmp") on the deck with `ranks` MPI ranks (mpirun for more than one) and
/// one OpenMP thread; nothing when it cannot run or its output is not understood (`why` says).
std::optional<LammpsRun> run_lammps(const std::string& command, const Plate& plate, int steps,
                                    int ranks, std::string& why);

}  // namespace dhpd::bench
