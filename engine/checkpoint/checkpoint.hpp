// Checkpoints: the whole state of a Simulation as bytes, and the versioned, checksummed file that
// carries it with the scene text and the caller's own run state (docs/checkpoint.md). Restoring
// into a Simulation built from the same setup continues bit for bit.
//
// File layout (native byte order, refused on a machine of the other order):
//   "DHPDCKPT" | u32 format version | u32 0x01020304 | u64 stored payload bytes | u64 checksum of
//   the stored payload (archive::Checksum: FNV-1a over 64-bit words)
//   payload: scene text | u64 setup fingerprint | simulation bytes | run-state bytes, stored in
//   LZ4 blocks of 1 MiB (payload_blocks.hpp; version 6 stored it as it is)
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/simulation.hpp"

namespace dhpd {

// 2: bond stiffness factors, crack tracks' initial angles and branch speeds;
// 3: refinement's search grid and event scratch left the state, the layout version entered;
// 4: interaction rows with one entry per neighbour pair;
// 5: the bond rows are the only bond store (no bond list or dual lists), stiffness in float;
// 6: the rows are built again from the particles on loading: only each row's entry count, the
//    entries' flags and factors (row order) and the stiffness scale are stored;
// 7: the payload in LZ4 blocks;
// 8: the loads hold each prescribed entry's displacement and condition (static runs,
//    displacement conditions, functions of time);
// 9: the rows' state-based dilatation factors (ordinary state-based level interfaces).
constexpr std::uint32_t kCheckpointVersion = 9;

/// The in-memory snapshot of a simulation (every array as it is, row arenas included).
std::vector<std::byte> save_simulation(const Simulation& sim);
/// The same snapshot written over `out`, in its memory when it is large enough (else `out` is
/// released before the new buffer is taken), so replacing a snapshot never holds two.
void save_simulation_into(const Simulation& sim, std::vector<std::byte>& out);
/// The size of save_simulation(sim), counted without writing it.
std::size_t simulation_snapshot_bytes(const Simulation& sim);

/// Bytes per particle and per own bond of a simulation's state, from what it stores: every
/// registered particle field, the bond constants, stable steps and break thresholds, one row
/// index per particle; per own bond one row entry (with equal horizons the rows hold as many
/// entries as own bonds; level-interface factors add 4 bytes per entry where they are solved). A
/// freshly built state is about particles × per_particle + bonds × per_bond (test: within a few
/// per cent of simulation_snapshot_bytes).
struct StateBytes {
  double per_particle = 0.0, per_bond = 0.0;
};
StateBytes state_bytes(ForceModel model);
/// Overwrites `sim` (built from the same setup) with a snapshot; throws InputError naming
/// `source` when the bytes are not a snapshot of a simulation of this setup.
void load_simulation(std::span<const std::byte> bytes, Simulation& sim,
                     const std::string& source = "snapshot");

/// A hash of what the setup's particles are made from (positions, cell measures, spacings,
/// materials, dimension): a changed points file or mesh gives another value.
std::uint64_t setup_fingerprint(const SimulationSetup& setup);

/// What a checkpoint file holds besides its header.
struct CheckpointParts {
  std::string scene_text;         ///< the resolved scene the run was started with
  std::uint64_t fingerprint = 0;  ///< setup_fingerprint of its setup
  std::span<const std::byte> simulation;
  std::span<const std::byte> run_state;  ///< the caller's (tools/run_checkpoint.hpp)
  /// The payload inflated from a file's LZ4 blocks, which the spans then point into (empty for
  /// a version-6 file: they point into its bytes).
  std::shared_ptr<const std::vector<std::byte>> inflated = nullptr;
};

/// Header, checksum and parts as one buffer (an in-memory checkpoint).
std::vector<std::byte> encode_checkpoint(const CheckpointParts& parts);
/// Checks magic, version, byte order, length and checksum; the spans point into `bytes` or into
/// the inflated payload the parts hold. Throws InputError naming `source` and what is wrong.
CheckpointParts decode_checkpoint(std::span<const std::byte> bytes, const std::string& source);

/// The checkpoint of `sim` streamed to `path` through an AtomicFile, without a serialised copy
/// in memory: the bytes of encode_checkpoint({scene_text, sim.fingerprint(),
/// save_simulation(sim), run_state}).
void write_checkpoint_file(const std::string& path, const std::string& scene_text,
                           const Simulation& sim, std::span<const std::byte> run_state,
                           const std::string& previous = {});

class AtomicFile;
/// write_checkpoint_file up to its commit: the whole file written and synced under its temporary
/// name, so that commit(previous) only renames it. Lets the caller finish other files first that
/// the checkpoint refers to (a frame), while this one is being written.
std::unique_ptr<AtomicFile> stage_checkpoint_file(const std::string& path,
                                                  const std::string& scene_text,
                                                  const Simulation& sim,
                                                  std::span<const std::byte> run_state);

/// A file written as `path.tmp` and renamed onto `path` by commit() (after fsync; the folder is
/// synced too). With `previous` non-empty, commit() first gives the old `path` that second name
/// (a hard link), so at every moment `path` names a complete file. Without commit() the
/// temporary file is removed.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  void write(std::span<const std::byte> bytes);
  void write_at(std::size_t offset, std::span<const std::byte> bytes);
  /// Flushes the temporary file to the disk and closes it (commit() does it when not done yet);
  /// nothing can be written after it.
  void sync();
  void commit(const std::string& previous = {});

 private:
  /// Writes of at least this many bytes start their writeback at once (sync_file_range).
  static constexpr std::size_t kStartWriteback = std::size_t{1} << 16;
  std::string path_, tmp_;
  int fd_ = -1;
  std::size_t written_ = 0;  ///< bytes write() appended
  bool synced_ = false, committed_ = false;
};

/// Writes `bytes` to `path` through an AtomicFile.
void write_file_atomically(const std::string& path, std::span<const std::byte> bytes,
                           const std::string& previous = {});

/// A whole file mapped read-only (a checkpoint is checked and read without a copy); throws
/// InputError when it cannot be opened.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::span<const std::byte> bytes() const { return {data_, size_}; }

 private:
  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace dhpd
