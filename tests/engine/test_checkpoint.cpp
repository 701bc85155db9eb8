// Engine checkpoints: N steps, snapshot, restore into a fresh Simulation, M more steps equals an
// uninterrupted N + M run byte for byte (2D fracture, 3D); damaged snapshots are refused; the
// payload is stored in LZ4 blocks and version-6 files are still read; a
// snapshot refreshes an old one in place; the fingerprint follows the particles. (With
// refinement events and re-sorts on both sides: tests/refine/test_checkpoint_events.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/archive.hpp"
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
  version[8] = static_cast<std::byte>(kCheckpointVersion + 1);  // a version this dhpd cannot read
  refused(version, "format version " + std::to_string(kCheckpointVersion + 1));
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

TEST(Checkpoint, PayloadIsStoredCompressed) {
  Simulation sim(pulled_plate());
  sim.run_steps(30);
  const auto snapshot = save_simulation(sim);
  const std::vector<std::byte> state{std::byte{4}, std::byte{5}};
  const CheckpointParts parts{"scene text", 11, snapshot, state};
  const auto file = encode_checkpoint(parts);
  // Constant fields and bond flags compress well: the plate's file is under half its payload.
  EXPECT_LT(2 * file.size(), snapshot.size() + state.size() + 10);
  const auto back = decode_checkpoint(file, "ck.bin");
  EXPECT_EQ(back.scene_text, "scene text");
  EXPECT_EQ(back.fingerprint, 11u);
  EXPECT_TRUE(std::ranges::equal(back.simulation, snapshot));
  EXPECT_TRUE(std::ranges::equal(back.run_state, state));
}

TEST(Checkpoint, MalformedBlocksWithAValidChecksumAreRefused) {
  Simulation sim(pulled_plate());
  const auto snapshot = save_simulation(sim);
  const auto file = encode_checkpoint({"scene", 1, snapshot, {}});
  constexpr std::size_t header = 32;
  // Edits the first block's sizes, then makes length and checksum fit again: only the block
  // check can refuse it (and it must, without reading past the end).
  const auto edited = [&](std::uint32_t raw, std::uint32_t stored, std::size_t cut = 0) {
    auto bytes = file;
    std::memcpy(bytes.data() + header, &raw, 4);
    std::memcpy(bytes.data() + header + 4, &stored, 4);
    bytes.resize(bytes.size() - cut);
    const std::uint64_t length = bytes.size() - header;
    const auto sum = archive::checksum(std::span(bytes).subspan(header));
    std::memcpy(bytes.data() + 16, &length, 8);
    std::memcpy(bytes.data() + 24, &sum, 8);
    try {
      decode_checkpoint(bytes, "ck.bin");
      return std::string("accepted");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
  };
  std::uint32_t sizes[2];
  std::memcpy(sizes, file.data() + header, 8);
  EXPECT_NE(edited(sizes[0], sizes[1]).find("accepted"), std::string::npos);
  EXPECT_NE(edited(0, sizes[1]).find("impossible size"), std::string::npos);
  EXPECT_NE(edited(sizes[0], 0xfffffff0u).find("cut short"), std::string::npos);
  EXPECT_NE(edited(sizes[0] - 1, sizes[1]).find("does not inflate"), std::string::npos);
  EXPECT_NE(edited(sizes[0], sizes[1], 3).find("ck.bin: not a valid checkpoint"),
            std::string::npos);
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
