// Engine checkpoints: N steps, snapshot, restore into a fresh Simulation, M more steps equals an
// uninterrupted N + M run byte for byte (2D fracture, 3D); damaged snapshots are refused; a
// snapshot refreshes an old one in place; the fingerprint follows the particles. (With
// refinement events and re-sorts on both sides: tests/refine/test_checkpoint_events.cpp.)
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

using test::expect_restart_exact;
using test::pulled_block_3d;
using test::pulled_plate;

/// A simulation stepped like the run loop does, without refinement.
struct Stepper {
  explicit Stepper(const SimulationSetup& setup) : sim(setup) {}
  void advance(std::int64_t steps) {
    for (std::int64_t k = 0; k < steps; ++k) sim.step();
  }
  Simulation sim;
  int events = 0, resorts = 0;
};

TEST(Checkpoint, FracturingPlateRestartsBitForBit) {
  expect_restart_exact<Stepper>(pulled_plate(), 120, 80);
}

TEST(Checkpoint, Block3dRestartsBitForBit) {
  expect_restart_exact<Stepper>(pulled_block_3d(), 60, 60);
}

TEST(Checkpoint, DamagedFilesAreRefused) {
  Simulation sim(pulled_plate());
  sim.run_steps(5);
  const auto snapshot = save_simulation(sim);
  const auto good = encode_checkpoint({"scene text", 7, snapshot, {}});
  const auto refused = [](std::vector<std::byte> bytes, const std::string& expected) {
    try {
      decode_checkpoint(bytes, "ck.bin");
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("ck.bin: ", 0), 0u) << e.what();
    }
  };
  EXPECT_NO_THROW(decode_checkpoint(good, "ck.bin"));
  refused({good.begin(), good.begin() + static_cast<long>(good.size() / 2)}, "truncated");
  refused({good.begin(), good.begin() + 10}, "header");
  auto flipped = good;
  flipped[flipped.size() / 2] ^= std::byte{0x10};
  refused(flipped, "checksum");
  auto version = good;
  version[8] = std::byte{9};
  refused(version, "format version 9");
  auto order = good;
  std::swap(order[12], order[15]);
  refused(order, "byte order");
  // A snapshot of another setup does not fit a simulation of this one.
  Simulation block(pulled_block_3d());
  EXPECT_THROW(load_simulation(snapshot, block, "ck.bin"), InputError);
  // Every prefix of a snapshot is refused without a crash or a huge allocation.
  Simulation fresh(pulled_plate());
  for (std::size_t cut = 0; cut < snapshot.size(); cut += 1 + snapshot.size() / 97)
    EXPECT_THROW(load_simulation(std::span(snapshot).first(cut), fresh, "ck.bin"), InputError);
}

TEST(Checkpoint, SnapshotIntoAnOldOneReusesItsMemory) {
  // The guard's last-good copy is refreshed in place: a run holds the state and one copy, never
  // a second copy while the first is replaced.
  auto setup = pulled_plate();
  Stepper run(setup);
  run.advance(10);
  std::vector<std::byte> kept;
  save_simulation_into(run.sim, kept);
  EXPECT_EQ(kept.size(), simulation_snapshot_bytes(run.sim));
  const std::byte* memory = kept.data();
  run.advance(10);  // same arrays, new values: the same size
  save_simulation_into(run.sim, kept);
  EXPECT_EQ(kept.data(), memory);
  EXPECT_EQ(kept, save_simulation(run.sim));
  // A snapshot larger than the old one's memory: the old one is released first.
  std::vector<std::byte> small(16);
  small.shrink_to_fit();
  save_simulation_into(run.sim, small);
  EXPECT_EQ(small, kept);
}

TEST(Checkpoint, FingerprintFollowsTheParticles) {
  auto a = pulled_plate();
  auto b = a;
  EXPECT_EQ(setup_fingerprint(a), setup_fingerprint(b));
  b.points.cell_measure[3] *= 1.0 + 1e-15;
  EXPECT_NE(setup_fingerprint(a), setup_fingerprint(b));
}

TEST(Checkpoint, TheSimulationKeepsTheFingerprintButNotThePoints) {
  // The particles hold the points once built; a copy in the setup would cost ~48 B per particle.
  const auto setup = pulled_plate();
  const Simulation sim(setup);
  EXPECT_EQ(sim.fingerprint(), setup_fingerprint(setup));
  EXPECT_EQ(sim.setup().points.size(), 0u);
  EXPECT_EQ(sim.setup().points.position.capacity(), 0u);
  EXPECT_EQ(sim.particles().size(), setup.points.size());
}

}  // namespace
}  // namespace dhpd
