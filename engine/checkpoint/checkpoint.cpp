// Simulation snapshots and the checkpoint file (see checkpoint.hpp).
#include "engine/checkpoint/checkpoint.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <functional>
#include <memory>

#include "engine/checkpoint/archive.hpp"
#include "engine/checkpoint/checkpoint_access.hpp"
#include "engine/checkpoint/payload_blocks.hpp"
#include "engine/physics/bond_loops.hpp"

namespace dhpd {

namespace archive {

namespace {
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

/// Words in the machine's byte order: a checkpoint is only read on a machine of the same order.
std::uint64_t mix(std::uint64_t h, const std::byte* word) {
  std::uint64_t w;
  std::memcpy(&w, word, 8);
  return (h ^ w) * kFnvPrime;
}
}  // namespace

void Checksum::add(std::span<const std::byte> bytes) {
  std::size_t at = 0;
  while (pending_size_ > 0 && pending_size_ < 8 && at < bytes.size())
    pending_[pending_size_++] = bytes[at++];
  if (pending_size_ == 8) h_ = mix(h_, pending_.data()), pending_size_ = 0;
  for (; at + 8 <= bytes.size(); at += 8) h_ = mix(h_, bytes.data() + at);
  while (at < bytes.size()) pending_[pending_size_++] = bytes[at++];
}

std::uint64_t Checksum::value() const {
  std::uint64_t h = h_;
  for (std::size_t k = 0; k < pending_size_; ++k)
    h = (h ^ static_cast<std::uint64_t>(pending_[k])) * kFnvPrime;
  return h;
}

std::uint64_t checksum(std::span<const std::byte> bytes) {
  Checksum c;
  c.add(bytes);
  return c.value();
}

void Reader::fail(const std::string& what) const {
  throw InputError(fmt::format("{}: not a valid checkpoint: {}", source_, what));
}

}  // namespace archive

std::vector<std::byte> save_simulation(const Simulation& sim) {
  std::vector<std::byte> out;
  save_simulation_into(sim, out);
  return out;
}

void save_simulation_into(const Simulation& sim, std::vector<std::byte>& out) {
  CheckpointAccess::save_into(sim, out,
                              [](const Simulation& s, auto& ar) { CheckpointAccess::save(s, ar); });
}

std::size_t simulation_snapshot_bytes(const Simulation& sim) {
  archive::Writer count(true);
  CheckpointAccess::save(sim, count);
  return count.size();
}

StateBytes state_bytes(ForceModel model) {
  StateBytes b;
  ParticleStore probe;
  for (const auto& f : probe.fields())
    b.per_particle += std::visit(
        [](const auto* data) -> double {
          using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
          if constexpr (std::is_same_v<T, VectorArray>)
            return 3.0 * sizeof(double);
          else
            return sizeof(typename T::value_type);
        },
        f.data);
  const double row_index = sizeof(std::int64_t) + 2 * sizeof(std::int32_t);
  // C, s0, stable step and the row's break threshold; one row index.
  b.per_particle += 4 * sizeof(double) + row_index;
  // One row entry per own bond (both rows of a pair hold one entry each, and each holds one own
  // bond): other, the index of 1/|ξ| in the length table, flags and the pair stiffness (the table
  // itself is small on a lattice; an irregular point set adds about 4 B per entry). The classical
  // models keep the dual side too (their rows list every pair), so the count is the same.
  (void)model;
  b.per_bond = 2 * sizeof(std::int32_t) + sizeof(std::uint8_t) + sizeof(float);
  return b;
}

void load_simulation(std::span<const std::byte> bytes, Simulation& sim, const std::string& source) {
  archive::Reader r(bytes, source);
  CheckpointAccess::load(sim, r);
}

std::uint64_t setup_fingerprint(const SimulationSetup& setup) {
  archive::Checksum sum;  // fed piece by piece: no serialised copy of the points
  archive::Writer w([&](std::span<const std::byte> bytes) { sum.add(bytes); });
  w(setup.section.dim), w(setup.points.position), w(setup.points.cell_measure);
  w(setup.points.spacing), w(setup.points.material);
  return sum.value();
}

namespace {

constexpr std::array<char, 8> kMagic = {'D', 'H', 'P', 'D', 'C', 'K', 'P', 'T'};
constexpr std::uint32_t kByteOrderMark = 0x01020304u;
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;

template <class T>
T read_at(std::span<const std::byte> bytes, std::size_t at) {
  T v;
  std::memcpy(&v, bytes.data() + at, sizeof(T));
  return v;
}

}  // namespace

namespace {

/// The header with the payload's length and checksum still 0 (set once the payload is written).
std::vector<std::byte> blank_header() {
  archive::Writer head;
  head(kMagic), head(kCheckpointVersion), head(kByteOrderMark);
  head(std::uint64_t{0}), head(std::uint64_t{0});
  return std::move(head.bytes());
}

/// Stores the payload (scene text, fingerprint, the simulation's bytes through `simulation`, the
/// run state) in LZ4 blocks through `sink`; returns the stored length and its checksum.
template <class SaveSimulation>
std::array<std::byte, 16> store_payload(
    const std::string& scene_text, std::uint64_t fingerprint, std::uint64_t simulation_bytes,
    SaveSimulation&& simulation, std::span<const std::byte> run_state,
    const std::function<void(std::span<const std::byte>)>& sink) {
  archive::Checksum sum;
  std::uint64_t length = 0;
  archive::BlockCompressor blocks([&](std::span<const std::byte> stored) {
    sum.add(stored);
    length += stored.size();
    sink(stored);
  });
  archive::Writer payload([&](std::span<const std::byte> bytes) { blocks.add(bytes); });
  payload(scene_text), payload(fingerprint), payload(simulation_bytes);
  simulation(payload);
  payload.section(run_state);
  blocks.finish();
  const std::uint64_t value = sum.value();
  std::array<std::byte, 16> tail;
  std::memcpy(tail.data(), &length, 8);
  std::memcpy(tail.data() + 8, &value, 8);
  return tail;
}

/// The parts of an archived payload; the spans point into `payload`.
CheckpointParts parse_payload(std::span<const std::byte> payload, const std::string& source) {
  archive::Reader r(payload, source);
  CheckpointParts parts;
  r(parts.scene_text), r(parts.fingerprint);
  parts.simulation = r.section();
  parts.run_state = r.section();
  if (r.remaining() != 0) r.fail("bytes left after the last section");
  return parts;
}

}  // namespace

std::vector<std::byte> encode_checkpoint(const CheckpointParts& parts) {
  auto bytes = blank_header();
  const auto tail = store_payload(
      parts.scene_text, parts.fingerprint, parts.simulation.size(),
      [&](archive::Writer& w) { w.raw_bytes(parts.simulation); }, parts.run_state,
      [&](std::span<const std::byte> b) { bytes.insert(bytes.end(), b.begin(), b.end()); });
  std::memcpy(bytes.data() + 16, tail.data(), tail.size());
  return bytes;
}

std::unique_ptr<AtomicFile> stage_checkpoint_file(const std::string& path,
                                                  const std::string& scene_text,
                                                  const Simulation& sim,
                                                  std::span<const std::byte> run_state) {
  archive::Writer count(true);
  CheckpointAccess::save(sim, count);
  auto file = std::make_unique<AtomicFile>(path);
  file->write(blank_header());
  const auto tail = store_payload(
      scene_text, sim.fingerprint(), count.size(),
      [&](archive::Writer& w) { CheckpointAccess::save(sim, w); }, run_state,
      [&](std::span<const std::byte> b) { file->write(b); });
  file->write_at(16, tail);
  file->sync();
  return file;
}

void write_checkpoint_file(const std::string& path, const std::string& scene_text,
                           const Simulation& sim, std::span<const std::byte> run_state,
                           const std::string& previous) {
  stage_checkpoint_file(path, scene_text, sim, run_state)->commit(previous);
}

CheckpointParts decode_checkpoint(std::span<const std::byte> bytes, const std::string& source) {
  const auto refuse = [&source](const std::string& why) {
    throw InputError(fmt::format("{}: not a valid checkpoint: {}", source, why));
  };
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0)
    refuse("it does not start with the dhpd checkpoint header");
  const auto version = read_at<std::uint32_t>(bytes, 8);
  if (read_at<std::uint32_t>(bytes, 12) != kByteOrderMark)
    refuse("it was written on a machine of the other byte order");
  if (version != kCheckpointVersion)
    refuse(
        fmt::format("format version {}, this dhpd reads version {}", version, kCheckpointVersion));
  const auto length = read_at<std::uint64_t>(bytes, 16);
  if (length != bytes.size() - kHeaderBytes)
    refuse(fmt::format("it is truncated or has extra bytes ({} payload bytes, the header says {})",
                       bytes.size() - kHeaderBytes, length));
  const auto payload = bytes.subspan(kHeaderBytes);
  if (archive::checksum(payload) != read_at<std::uint64_t>(bytes, 24))
    refuse("the checksum does not match (the file is corrupted)");
  auto inflated =
      std::make_shared<const std::vector<std::byte>>(archive::inflate_blocks(payload, source));
  auto parts = parse_payload(*inflated, source);
  parts.inflated = std::move(inflated);
  return parts;
}

}  // namespace dhpd
