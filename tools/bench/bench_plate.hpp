// The bodies `dhpd bench` times: the Kalthoff–Winkler plate of the LAMMPS deck, shared by the
// threads and the MPI benchmarks.
#pragma once
#include "engine/simulation.hpp"
#include "tools/bench/lammps_deck.hpp"

namespace dhpd::bench {

/// A 3D bond-based setup of one material, linear partial volumes (the bonds |ξ| ≤ δ that LAMMPS's
/// peri/pmb builds), fracture on or off.
SimulationSetup common_setup(double horizon_factor, const Material& m, bool fracture);
/// The plate of bench::Plate: the same sites, notches and impact as the LAMMPS deck.
SimulationSetup plate_setup(const Plate& plate, bool fracture);

}  // namespace dhpd::bench
