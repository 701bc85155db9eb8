// Checkpoints of an adaptive run: a restart is bit for bit the uninterrupted run with refinement
// events and re-sorts on both sides of the snapshot, and the streamed checkpoint file holds the
// bytes of the in-memory one after events (the engine's own checkpoint tests:
// tests/engine/test_checkpoint.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "engine/checkpoint/checkpoint.hpp"
#include "refine/refiner.hpp"
#include "tests/support/adaptive_run.hpp"
#include "tests/support/checkpoint.hpp"

namespace dhpd {
namespace {

using test::expect_restart_exact;
using test::pulled_plate;

using Stepper = test::AdaptiveRun;

TEST(Checkpoint, AdaptivePlateRestartsBitForBitWithEventsAndResortOnBothSides) {
  auto setup = pulled_plate();
  setup.resort_fraction = 0.02;  // re-sorts after most events
  const auto ev = expect_restart_exact<Stepper>(setup, 110, 150);
  EXPECT_GE(ev.before, 2) << "events before the checkpoint";
  EXPECT_GE(ev.total - ev.before, 2) << "events after the checkpoint";
  EXPECT_GE(ev.resorts_before, 1) << "a re-sort before the checkpoint";
  EXPECT_GE(ev.resorts_total - ev.resorts_before, 1) << "a re-sort after the checkpoint";
  std::cerr << "events " << ev.before << " + " << ev.total - ev.before << ", re-sorts "
            << ev.resorts_before << " + " << ev.resorts_total - ev.resorts_before << "\n";
}

TEST(Checkpoint, StreamedFileHoldsTheBytesOfTheInMemoryCheckpoint) {
  auto setup = pulled_plate();
  Stepper run(setup);
  run.advance(40);
  ASSERT_GT(run.events, 0);
  const std::vector<std::byte> state{std::byte{1}, std::byte{2}, std::byte{3}};
  const auto path = (std::filesystem::temp_directory_path() /
                     ("dhpd_checkpoint_" + std::to_string(::getpid()) + ".bin"))
                        .string();
  write_checkpoint_file(path, "scene", run.sim, state);
  const auto snapshot = save_simulation(run.sim);
  const auto expected = encode_checkpoint({"scene", setup_fingerprint(setup), snapshot, state});
  {
    const MappedFile file(path);
    const auto bytes = file.bytes();
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), expected.begin(), expected.end()));
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace dhpd
