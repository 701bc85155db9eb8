// Shared by the engine's and refinement's checkpoint tests: two pulled setups, a bit-for-bit
// comparison of two simulations (every array, then the whole snapshot) and the restart check
// (N steps, snapshot through a checkpoint file's bytes, restore, M more = an uninterrupted N + M).
#pragma once
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdint>
#include <cstring>
#include <iostream>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "engine/checkpoint/checkpoint.hpp"
#include "engine/simulation.hpp"
#include "geometry/lattice.hpp"

namespace dhpd::test {

using geometry::Box;

/// The top and bottom layers pulled apart along y: by tractions ±load (Pa) or velocities ±load.
inline void pull_apart(SimulationSetup& s, BoundaryCondition::Kind kind, const Box& top_layer,
                       const Box& bottom_layer, double load) {
  BoundaryCondition top, bottom;
  top.kind = bottom.kind = kind;
  top.region = top_layer;
  bottom.region = bottom_layer;
  top.normal_axis = bottom.normal_axis = 1;
  if (kind == BoundaryCondition::Kind::Traction) {
    top.traction = {0, load, 0};
    bottom.traction = {0, -load, 0};
  } else {
    top.velocity[1] = load;
    bottom.velocity[1] = -load;
  }
  s.boundary_conditions = {top, bottom};
  s.effects.fracture = true;
}

/// A pre-cracked 30 mm x 12 mm glass plate at 0.5 mm, torn open by 25 MPa.
inline SimulationSetup pulled_plate() {
  SimulationSetup s;
  s.section = {2, PlaneMode::Stress, 1e-3, 1};
  s.materials = {{72e9, 2440, 3.8}};
  s.partial_volume = PartialVolume::Linear;
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.03, 0.012, 0}}, 5e-4, 0}}, 2);
  s.cracks = {{{{0.0, 0.006, 0}, {0.012, 0.006, 0}}}};
  pull_apart(s, BoundaryCondition::Kind::Traction, Box{{0, 0.0105, 0}, {0.03, 0.012, 0}},
             Box{{0, 0, 0}, {0.03, 0.0015, 0}}, 25e6);
  return s;
}

/// An 8 x 8 x 4 mm glass block at 0.5 mm whose faces move apart at ±0.5 m/s.
inline SimulationSetup pulled_block_3d() {
  SimulationSetup s;
  s.section = {3, PlaneMode::Stress, 1, 1};
  s.materials = {{72e9, 2440, 3.8}};
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.008, 0.008, 0.004}}, 5e-4, 0}}, 3);
  pull_apart(s, BoundaryCondition::Kind::Velocity, Box{{0, 0.007, 0}, {0.008, 0.008, 0.004}},
             Box{{0, 0, 0}, {0.008, 0.001, 0.004}}, 0.5);
  return s;
}

template <class T>
inline void expect_same_bytes(const std::vector<T>& a, const std::vector<T>& b,
                              const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_TRUE(a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0) << what;
}

/// 1/|ξ| of every slot of the rows (0 for a slot outside every row): comparable between rows
/// whose length tables list the same values in another order.
inline std::vector<double> entry_lengths(const BondRows& b) {
  std::vector<double> out(b.other.size(), 0.0);
  for (std::size_t i = 0; i < b.particles(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      out[static_cast<std::size_t>(k)] = b.inverse_length(k);
  return out;
}

inline void expect_same_rows(const RowIndex& a, const RowIndex& b, const std::string& what) {
  expect_same_bytes(a.start, b.start, what + " start");
  expect_same_bytes(a.count, b.count, what + " count");
  expect_same_bytes(a.capacity, b.capacity, what + " capacity");
  EXPECT_EQ(a.arena, b.arena) << what;
  EXPECT_EQ(a.garbage, b.garbage) << what;
}

inline std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, 8);
  return b;
}

/// Every public array and number, compared bit for bit; then the whole snapshot (private members
/// too), with the wall-clock phase timers cleared on both sides.
inline void expect_identical(Simulation& a, Simulation& b) {
  auto fa = a.particles().fields(), fb = b.particles().fields();
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t f = 0; f < fa.size(); ++f)
    std::visit(
        [&](const auto* x) {
          using A = std::remove_cv_t<std::remove_pointer_t<decltype(x)>>;
          const auto* y = std::get<A*>(fb[f].data);
          if constexpr (std::is_same_v<A, VectorArray>) {
            for (int c = 0; c < 3; ++c)
              expect_same_bytes((*x)[c], (*y)[c], std::string(fa[f].name));
          } else {
            expect_same_bytes(*x, *y, std::string(fa[f].name));
          }
        },
        fa[f].data);
  const auto &ba = a.bonds(), &bb = b.bonds();
  expect_same_rows(ba.rows, bb.rows, "bond rows");
  expect_same_bytes(ba.other, bb.other, "row other");
  expect_same_bytes(entry_lengths(ba), entry_lengths(bb), "row 1/length");
  expect_same_bytes(ba.flags, bb.flags, "row flags");
  expect_same_bytes(ba.factor, bb.factor, "row factors");
  expect_same_bytes(ba.stiffness, bb.stiffness, "row stiffness");
  expect_same_bytes(ba.break_ratio2, bb.break_ratio2, "row break thresholds");
  EXPECT_EQ(bits(ba.stiffness_scale), bits(bb.stiffness_scale));
  EXPECT_EQ(ba.live, bb.live);
  EXPECT_EQ(ba.own_bonds, bb.own_bonds);
  expect_same_bytes(a.micromodulus(), b.micromodulus(), "C");
  expect_same_bytes(a.critical_stretch(), b.critical_stretch(), "s0");
  EXPECT_EQ(bits(a.time()), bits(b.time()));
  EXPECT_EQ(bits(a.dt()), bits(b.dt()));
  EXPECT_EQ(bits(a.critical_dt()), bits(b.critical_dt()));
  EXPECT_EQ(a.steps_done(), b.steps_done());
  EXPECT_EQ(a.broken_bonds(), b.broken_bonds());
  EXPECT_EQ(a.generation(), b.generation());
  EXPECT_EQ(a.bond_updates(), b.bond_updates());
  const auto ea = a.energies(), eb = b.energies();
  EXPECT_EQ(bits(ea.kinetic), bits(eb.kinetic));
  EXPECT_EQ(bits(ea.strain), bits(eb.strain));
  EXPECT_EQ(bits(ea.external_work), bits(eb.external_work));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(bits(ea.momentum[c]), bits(eb.momentum[c]));
  a.timers() = PhaseTimers{};
  b.timers() = PhaseTimers{};
  EXPECT_TRUE(save_simulation(a) == save_simulation(b)) << "the snapshots differ";
}

struct Events {
  int before = 0, resorts_before = 0, total = 0, resorts_total = 0;
};

/// `whole` (n + m steps from `setup`) against a run saved after n steps, loaded into a fresh
/// simulation and stepped m more, and against the same n + m steps on one thread: bit for bit.
inline void expect_restart_and_one_thread_exact(const SimulationSetup& setup, Simulation& whole,
                                                std::int64_t n, std::int64_t m) {
  Simulation first(setup);
  first.run_steps(n);
  const auto snapshot = save_simulation(first);
  Simulation second(setup);
  load_simulation(snapshot, second, "test");
  second.run_steps(m);
  expect_identical(second, whole);
  omp_set_num_threads(1);
  Simulation one(setup);
  one.run_steps(n + m);
  omp_set_num_threads(omp_get_num_procs());
  expect_identical(one, whole);
}

/// N steps, a snapshot through a checkpoint file's bytes, restored into a fresh simulation built
/// from the same setup, M more steps on both: the same state as an uninterrupted run.
/// `Stepper` (built from the setup) has `sim`, `advance(steps)` and counts `events`, `resorts`.
template <class Stepper>
Events expect_restart_exact(const SimulationSetup& setup, std::int64_t n, std::int64_t m) {
  Stepper whole(setup);
  whole.advance(n + m);
  Stepper first(setup);
  first.advance(n);
  const auto snapshot = save_simulation(first.sim);
  const auto file = encode_checkpoint({"scene", setup_fingerprint(setup), snapshot, {}});
  Stepper second(setup);  // a fresh object: its own from-scratch build
  const auto parts = decode_checkpoint(file, "test");
  load_simulation(parts.simulation, second.sim, "test");
  second.advance(m);
  EXPECT_EQ(first.events + second.events, whole.events);
  EXPECT_GT(whole.sim.broken_bonds(), first.sim.broken_bonds());  // fracture goes on after it
  EXPECT_GT(first.sim.broken_bonds(), 0);
  expect_identical(second.sim, whole.sim);
  std::cerr << "particles " << whole.sim.particles().size() << ", broken "
            << first.sim.broken_bonds() << " -> " << whole.sim.broken_bonds() << "\n";
  return {first.events, first.resorts, whole.events, whole.resorts};
}

}  // namespace dhpd::test
