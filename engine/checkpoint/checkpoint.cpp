// Simulation snapshots and the checkpoint file (see checkpoint.hpp).
#include "engine/checkpoint/checkpoint.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "engine/checkpoint/archive.hpp"
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

/// Every member of a Simulation that decides its future, in one list for writing and reading.
struct CheckpointAccess {
  template <class Rows, class Ar>
  static void rows(Rows& r, Ar& ar) {
    ar(r.start), ar(r.count), ar(r.capacity), ar(r.arena), ar(r.garbage);
  }

  template <class Sim, class Ar>
  static void members(Sim& s, Ar& ar) {
    rows(s.bonds_.rows, ar);
    ar(s.bonds_.owner), ar(s.bonds_.neighbor), ar(s.bonds_.length), ar(s.bonds_.weight);
    ar(s.bonds_.intact), ar(s.bonds_.stiffness), ar(s.bonds_.live);
    rows(s.dual_.rows, ar);
    ar(s.dual_.bond);
    rows(s.il_.rows, ar);
    ar(s.il_.other), ar(s.il_.inv_length), ar(s.il_.coefficient), ar(s.il_.break_at);
    ar(s.il_.own_bond), ar(s.il_.dual_bond), ar(s.il_.alive), ar(s.il_.live);
    auto& l = s.loads_;
    ar(l.prescribed), ar(l.mask), ar(l.prescribed_velocity), ar(l.loaded), ar(l.body_force);
    ar(l.condition_body_force);
    ar(s.C_), ar(s.s0_), ar(s.particle_dt_);
    ar(s.reach_), ar(s.max_horizon_), ar(s.appended_since_compaction_), ar(s.layout_version_);
    ar(s.time_), ar(s.dt_), ar(s.critical_dt_);
    ar(s.external_work_), ar(s.last_power_);
    ar(s.budget_.tolerance), ar(s.budget_.initial), ar(s.budget_.mapping), ar(s.budget_.scale);
    ar(s.conservative_), ar(s.blowup_factor_);
    ar(s.steps_), ar(s.broken_), ar(s.bond_updates_), ar(s.generation_), ar(s.next_id_);
  }

  template <class Ar>
  static void save(const Simulation& s, Ar& ar) {
    ar(static_cast<std::int32_t>(s.p_.dim()));
    // fields() hands out pointers for writing; here they are only read.
    for (const auto& f : const_cast<ParticleStore&>(s.p_).fields()) {
      ar(std::string(f.name));
      std::visit([&ar](const auto* data) { ar(*data); }, f.data);
    }
    members(s, ar);
    std::array<double, static_cast<int>(Phase::Count)> seconds{};
    for (int k = 0; k < static_cast<int>(Phase::Count); ++k)
      seconds[k] = s.timers_.seconds(static_cast<Phase>(k));
    ar(seconds);
  }

  static void load(Simulation& s, archive::Reader& ar) {
    std::int32_t dim = 0;
    ar(dim);
    if (dim != s.p_.dim())
      ar.fail(fmt::format("it is a {}D run, this scene is {}D", dim, s.p_.dim()));
    for (auto& f : s.p_.fields()) {
      std::string name;
      ar(name);
      if (name != f.name)
        ar.fail(fmt::format("particle field '{}' where '{}' was expected", name, f.name));
      std::visit([&ar](auto* data) { ar(*data); }, f.data);
    }
    members(s, ar);
    std::array<double, static_cast<int>(Phase::Count)> seconds{};
    ar(seconds);
    s.timers_ = PhaseTimers{};
    for (int k = 0; k < static_cast<int>(Phase::Count); ++k)
      s.timers_.add(static_cast<Phase>(k), seconds[k]);
    if (ar.remaining() != 0) ar.fail("bytes left after the simulation state");
    check_consistent(s, ar);
    s.touched_.assign(s.p_.size(), 0);
    s.edit_.reset();
    // Damage is kept current by the stepper; format-4 files may hold an older value.
    if (s.setup_.effects.fracture) compute_damage(s.bonds_, s.p_);
  }

  template <class V>
  static bool in_range(const V& v, std::int64_t lo, std::int64_t hi) {
    return std::all_of(v.begin(), v.end(), [&](auto x) { return x >= lo && x < hi; });
  }

  /// Row i of every one of n rows lies inside an arena of `slots` entries.
  static bool rows_fit(const RowIndex& r, std::size_t n, std::size_t slots) {
    if (r.rows() != n || r.count.size() != n || r.capacity.size() != n) return false;
    if (r.arena < 0 || static_cast<std::size_t>(r.arena) != slots) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (r.start[i] < 0 || r.count[i] < 0 || r.count[i] > r.capacity[i] ||
          r.start[i] + r.capacity[i] > r.arena)
        return false;
    return true;
  }

  static bool particles_fit(const Simulation& s) {
    const std::size_t n = s.p_.size();
    for (auto& f : const_cast<ParticleStore&>(s.p_).fields()) {
      const bool sized = std::visit(
          [n](const auto* data) {
            if constexpr (std::is_same_v<std::decay_t<decltype(*data)>, VectorArray>)
              return (*data)[0].size() == n && (*data)[1].size() == n && (*data)[2].size() == n;
            else
              return data->size() == n;
          },
          f.data);
      if (!sized) return false;
    }
    const auto materials = static_cast<std::int64_t>(s.setup_.materials.size());
    return in_range(s.p_.material, 0, materials) && s.C_.size() == n && s.s0_.size() == n &&
           s.particle_dt_.size() == n;
  }

  /// Sizes and indices agree with each other, so no later access leaves the arrays.
  static void check_consistent(const Simulation& s, const archive::Reader& ar) {
    if (!particles_fit(s)) ar.fail("its particle arrays do not fit together");
    const auto n = static_cast<std::int64_t>(s.p_.size());
    const auto& b = s.bonds_;
    const std::size_t slots = b.neighbor.size();
    const auto& il = s.il_;
    const std::size_t entries = il.other.size();
    const auto& l = s.loads_;
    const bool ok = rows_fit(b.rows, s.p_.size(), slots) && b.owner.size() == slots &&
                    b.length.size() == slots && b.weight.size() == slots &&
                    b.intact.size() == slots && b.stiffness.size() == slots &&
                    in_range(b.owner, -1, n) && in_range(b.neighbor, -1, n) &&
                    rows_fit(s.dual_.rows, s.p_.size(), s.dual_.bond.size()) &&
                    in_range(s.dual_.bond, -1, static_cast<std::int64_t>(slots)) &&
                    rows_fit(il.rows, s.p_.size(), entries) && il.inv_length.size() == entries &&
                    il.coefficient.size() == entries && il.break_at.size() == entries &&
                    il.own_bond.size() == entries && il.dual_bond.size() == entries &&
                    il.alive.size() == entries && in_range(il.other, -1, n) &&
                    in_range(il.own_bond, -1, static_cast<std::int64_t>(slots)) &&
                    in_range(il.dual_bond, -1, static_cast<std::int64_t>(slots)) &&
                    in_range(l.prescribed, 0, n) && in_range(l.loaded, 0, n) &&
                    l.mask.size() == l.prescribed.size() &&
                    l.prescribed_velocity.size() == l.prescribed.size() &&
                    l.body_force.size() == l.loaded.size();
    if (!ok) ar.fail("its bond, dual, interaction or load arrays do not fit together");
  }
};

std::vector<std::byte> save_simulation(const Simulation& sim) {
  std::vector<std::byte> out;
  save_simulation_into(sim, out);
  return out;
}

void save_simulation_into(const Simulation& sim, std::vector<std::byte>& out) {
  const std::size_t n = simulation_snapshot_bytes(sim);
  if (n > out.capacity()) std::vector<std::byte>().swap(out);
  archive::Writer w(std::move(out));
  w.reserve(n);
  CheckpointAccess::save(sim, w);
  out = std::move(w.bytes());
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
  b.per_particle += 3 * sizeof(double) + 3 * row_index;  // C, s0, stable step; three row arenas
  const double bond_row = 2 * sizeof(std::int32_t) + 3 * sizeof(double) + sizeof(std::uint8_t);
  const double interaction = sizeof(std::int32_t) + 2 * sizeof(double);
  const double entries = model == ForceModel::DualHorizon ? 2.0 : 1.0;
  b.per_bond = bond_row + sizeof(BondId) + entries * interaction + 2 * sizeof(std::int64_t);
  return b;
}

void load_simulation(std::span<const std::byte> bytes, Simulation& sim, const std::string& source) {
  archive::Reader r(bytes, source);
  CheckpointAccess::load(sim, r);
}

std::uint64_t setup_fingerprint(const SimulationSetup& setup) {
  archive::Writer w;
  w(setup.section.dim), w(setup.points.position), w(setup.points.cell_measure);
  w(setup.points.spacing), w(setup.points.material);
  return archive::checksum(w.bytes());
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
  payload(scene_text), payload(setup_fingerprint(sim.setup()));
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
