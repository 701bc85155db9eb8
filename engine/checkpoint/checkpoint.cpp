// Simulation snapshots and the checkpoint file (see checkpoint.hpp).
#include "engine/checkpoint/checkpoint.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "engine/checkpoint/archive.hpp"
#include "engine/checkpoint/checkpoint_access.hpp"
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

/// The file as pieces: header, then the scene text, fingerprint and the simulation's size; the
/// simulation; the run state's size; the run state. The parts are not copied.
struct Pieces {
  std::vector<std::byte> head, middle;
  std::array<std::span<const std::byte>, 4> all() const {
    return {std::span(head), simulation, std::span(middle), run_state};
  }
  std::span<const std::byte> simulation, run_state;
};

Pieces checkpoint_pieces(const CheckpointParts& parts) {
  archive::Writer head, middle;
  head(kMagic), head(kCheckpointVersion), head(kByteOrderMark);
  head(std::uint64_t{0}), head(std::uint64_t{0});  // payload length and checksum, filled below
  head(parts.scene_text), head(parts.fingerprint);
  head(static_cast<std::uint64_t>(parts.simulation.size()));
  middle(static_cast<std::uint64_t>(parts.run_state.size()));
  Pieces p{std::move(head.bytes()), std::move(middle.bytes()), parts.simulation, parts.run_state};
  archive::Checksum sum;
  std::uint64_t length = 0;
  const auto all = p.all();
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto payload = k == 0 ? all[0].subspan(kHeaderBytes) : all[k];
    sum.add(payload);
    length += payload.size();
  }
  const std::uint64_t value = sum.value();
  std::memcpy(p.head.data() + 16, &length, 8);
  std::memcpy(p.head.data() + 24, &value, 8);
  return p;
}

}  // namespace

std::vector<std::byte> encode_checkpoint(const CheckpointParts& parts) {
  const auto pieces = checkpoint_pieces(parts);
  std::vector<std::byte> bytes;
  for (const auto piece : pieces.all()) bytes.insert(bytes.end(), piece.begin(), piece.end());
  return bytes;
}

void write_checkpoint_file(const std::string& path, const std::string& scene_text,
                           const Simulation& sim, std::span<const std::byte> run_state,
                           const std::string& previous) {
  archive::Writer count(true);
  CheckpointAccess::save(sim, count);
  AtomicFile file(path);
  archive::Writer head;
  head(kMagic), head(kCheckpointVersion), head(kByteOrderMark);
  head(std::uint64_t{0}), head(std::uint64_t{0});  // payload length and checksum, set below
  file.write(head.bytes());
  // The payload goes through a buffer to the file, summed on the way.
  std::vector<std::byte> buffer;
  buffer.reserve(std::size_t{1} << 20);
  archive::Checksum sum;
  std::uint64_t length = 0;
  const auto flush = [&] {
    file.write(buffer);
    buffer.clear();
  };
  archive::Writer payload([&](std::span<const std::byte> bytes) {
    sum.add(bytes);
    length += bytes.size();
    if (buffer.size() + bytes.size() > buffer.capacity()) flush();
    if (bytes.size() >= buffer.capacity())
      file.write(bytes);
    else
      buffer.insert(buffer.end(), bytes.begin(), bytes.end());
  });
  payload(scene_text), payload(sim.fingerprint());
  payload(static_cast<std::uint64_t>(count.size()));
  CheckpointAccess::save(sim, payload);
  payload.section(run_state);
  flush();
  const std::uint64_t value = sum.value();
  std::array<std::byte, 16> tail;
  std::memcpy(tail.data(), &length, 8);
  std::memcpy(tail.data() + 8, &value, 8);
  file.write_at(16, tail);
  file.commit(previous);
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
  archive::Reader r(payload, source);
  CheckpointParts parts;
  r(parts.scene_text), r(parts.fingerprint);
  parts.simulation = r.section();
  parts.run_state = r.section();
  if (r.remaining() != 0) r.fail("bytes left after the last section");
  return parts;
}

}  // namespace dhpd
