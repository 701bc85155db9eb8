// Engine checkpoints: N steps, snapshot, restore into a fresh Simulation, M more steps equals an
// uninterrupted N + M run byte for byte (2D fracture, adaptive refinement with events and a
// re-sort on both sides of the snapshot, 3D); damaged snapshots are refused.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "refine/refiner.hpp"
#include "tests/support.hpp"

namespace dhpd {
namespace {

using geometry::Box;

/// The top and bottom layers pulled apart along y: by tractions ±load (Pa) or velocities ±load.
void pull_apart(SimulationSetup& s, BoundaryCondition::Kind kind, const Box& top_layer,
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
SimulationSetup pulled_plate() {
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
SimulationSetup pulled_block_3d() {
  SimulationSetup s;
  s.section = {3, PlaneMode::Stress, 1, 1};
  s.materials = {{72e9, 2440, 3.8}};
  s.points = geometry::fill_lattice({{Box{{0, 0, 0}, {0.008, 0.008, 0.004}}, 5e-4, 0}}, 3);
  pull_apart(s, BoundaryCondition::Kind::Velocity, Box{{0, 0.007, 0}, {0.008, 0.008, 0.004}},
             Box{{0, 0, 0}, {0.008, 0.001, 0.004}}, 0.5);
  return s;
}

/// A simulation with an optional damage-triggered refiner, stepped like the run loop does.
struct Stepper {
  explicit Stepper(const SimulationSetup& setup, bool adaptive = false) : sim(setup) {
    if (!adaptive) return;
    refine::Settings set;
    set.trigger.damage = 0.02;
    set.max_level = 1;
    set.check_every = 5;
    refiner.emplace(set);
  }
  void advance(std::int64_t steps) {
    for (std::int64_t k = 0; k < steps; ++k) {
      sim.step();
      if (!refiner || !refiner->due(sim.steps_done())) continue;
      const auto ev = refiner->check(sim);
      events += ev.parents > 0 ? 1 : 0;
      resorts += ev.resorted ? 1 : 0;
    }
  }
  Simulation sim;
  std::optional<refine::Refiner> refiner;
  int events = 0, resorts = 0;
};

template <class T>
void expect_same_bytes(const std::vector<T>& a, const std::vector<T>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_TRUE(a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0) << what;
}

void expect_same_rows(const RowIndex& a, const RowIndex& b, const std::string& what) {
  expect_same_bytes(a.start, b.start, what + " start");
  expect_same_bytes(a.count, b.count, what + " count");
  expect_same_bytes(a.capacity, b.capacity, what + " capacity");
  EXPECT_EQ(a.arena, b.arena) << what;
  EXPECT_EQ(a.garbage, b.garbage) << what;
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, 8);
  return b;
}

/// Every public array and number, compared bit for bit; then the whole snapshot (private members
/// too), with the wall-clock phase timers cleared on both sides.
void expect_identical(Simulation& a, Simulation& b) {
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
  expect_same_bytes(ba.owner, bb.owner, "bond owner");
  expect_same_bytes(ba.neighbor, bb.neighbor, "bond neighbour");
  expect_same_bytes(ba.length, bb.length, "bond length");
  expect_same_bytes(ba.weight, bb.weight, "bond weight");
  expect_same_bytes(ba.intact, bb.intact, "bond intact");
  expect_same_rows(a.dual().rows, b.dual().rows, "dual rows");
  expect_same_bytes(a.dual().bond, b.dual().bond, "dual bonds");
  const auto &ia = a.interactions(), &ib = b.interactions();
  expect_same_rows(ia.rows, ib.rows, "interaction rows");
  expect_same_bytes(ia.other, ib.other, "interaction other");
  expect_same_bytes(ia.coefficient, ib.coefficient, "interaction coefficient");
  expect_same_bytes(ia.inv_length, ib.inv_length, "interaction 1/length");
  expect_same_bytes(ia.own_slot, ib.own_slot, "own slots");
  expect_same_bytes(ia.dual_slot, ib.dual_slot, "dual slots");
  expect_same_bytes(a.micromodulus(), b.micromodulus(), "C");
  expect_same_bytes(a.critical_stretch(), b.critical_stretch(), "s0");
  EXPECT_EQ(bits(a.time()), bits(b.time()));
  EXPECT_EQ(bits(a.dt()), bits(b.dt()));
  EXPECT_EQ(bits(a.critical_dt()), bits(b.critical_dt()));
  EXPECT_EQ(a.steps_done(), b.steps_done());
  EXPECT_EQ(a.broken_bonds(), b.broken_bonds());
  EXPECT_EQ(a.generation(), b.generation());
  EXPECT_EQ(a.interaction_updates(), b.interaction_updates());
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

/// N steps, a snapshot through a checkpoint file's bytes, restored into a fresh simulation built
/// from the same setup, M more steps on both: the same state as an uninterrupted run.
Events expect_restart_exact(const SimulationSetup& setup, bool adaptive, std::int64_t n,
                            std::int64_t m) {
  Stepper whole(setup, adaptive);
  whole.advance(n + m);
  Stepper first(setup, adaptive);
  first.advance(n);
  const auto snapshot = save_simulation(first.sim);
  const auto file = encode_checkpoint({"scene", setup_fingerprint(setup), snapshot, {}});
  Stepper second(setup, adaptive);  // a fresh object: its own from-scratch build
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

TEST(Checkpoint, FracturingPlateRestartsBitForBit) {
  expect_restart_exact(pulled_plate(), false, 120, 80);
}

TEST(Checkpoint, AdaptivePlateRestartsBitForBitWithEventsAndResortOnBothSides) {
  auto setup = pulled_plate();
  setup.resort_fraction = 0.02;  // re-sorts after most events
  const auto ev = expect_restart_exact(setup, true, 110, 150);
  EXPECT_GE(ev.before, 2) << "events before the checkpoint";
  EXPECT_GE(ev.total - ev.before, 2) << "events after the checkpoint";
  EXPECT_GE(ev.resorts_before, 1) << "a re-sort before the checkpoint";
  EXPECT_GE(ev.resorts_total - ev.resorts_before, 1) << "a re-sort after the checkpoint";
  std::cerr << "events " << ev.before << " + " << ev.total - ev.before << ", re-sorts "
            << ev.resorts_before << " + " << ev.resorts_total - ev.resorts_before << "\n";
}

TEST(Checkpoint, Block3dRestartsBitForBit) {
  expect_restart_exact(pulled_block_3d(), false, 60, 60);
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

TEST(Checkpoint, StreamedFileHoldsTheBytesOfTheInMemoryCheckpoint) {
  auto setup = pulled_plate();
  Stepper run(setup, true);
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

TEST(Checkpoint, SnapshotIntoAnOldOneReusesItsMemory) {
  // The guard's last-good copy is refreshed in place: a run holds the state and one copy, never
  // a second copy while the first is replaced.
  auto setup = pulled_plate();
  Stepper run(setup, false);
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

}  // namespace
}  // namespace dhpd
