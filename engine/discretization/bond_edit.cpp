// Replacing the own bonds of some owners in the bond rows (the incremental rebuild of a refinement
// event, docs/theory.md §13.6): every row that holds one of those bonds, own or dual, is merged
// anew and written back in place or, when it grew, at the end of the arena.
#include <algorithm>

#include "engine/base/errors.hpp"
#include "engine/discretization/bonds.hpp"
#include "engine/discretization/length_table.hpp"

namespace dhpd {

namespace {

/// One entry of a row being merged.
struct Entry {
  std::int32_t other;
  std::uint8_t flags;
  float factor;
  float dilatation;  ///< the own bond's state-based dilatation factor
};

/// A new bond seen from its neighbour's row. An owner has one bond to a neighbour, so (neighbour,
/// owner) orders them all.
struct DualSide {
  std::int32_t neighbour, owner;
  bool intact;
  std::int64_t key() const {
    return (static_cast<std::int64_t>(neighbour) << 32) | static_cast<std::uint32_t>(owner);
  }
};

bool among(const std::vector<std::int32_t>& sorted, std::int32_t x) {
  return std::binary_search(sorted.begin(), sorted.end(), x);
}

/// Row t after the replacement: its current entries without the replaced bonds, then the new ones.
void merge_row(const BondRows& b, std::int32_t t, const std::vector<std::int32_t>& owners,
               const std::vector<NewBond>* own_new, const DualSide* dual_first,
               const DualSide* dual_last, std::vector<Entry>& out) {
  out.clear();
  const auto u = static_cast<std::size_t>(t);
  const bool rewritten = own_new != nullptr;
  constexpr auto own_bits = static_cast<std::uint8_t>(kOwn | kOwnIntact);
  constexpr auto dual_bits = static_cast<std::uint8_t>(kDual | kDualIntact);
  for (auto k = b.begin(u); k < b.end(u); ++k) {
    auto f = b.flags[k];
    if (rewritten) f = static_cast<std::uint8_t>(f & ~own_bits);
    if (among(owners, b.other[k])) f = static_cast<std::uint8_t>(f & ~dual_bits);
    if (f)
      out.push_back({b.other[k], f, f & kOwn ? static_cast<float>(b.own_factor(k)) : 1.0f,
                     f & kOwn ? static_cast<float>(b.own_dilatation_factor(k)) : 1.0f});
  }
  auto entry_of = [&](std::int32_t j) -> Entry& {
    const auto it = std::lower_bound(out.begin(), out.end(), j,
                                     [](const Entry& e, std::int32_t x) { return e.other < x; });
    if (it != out.end() && it->other == j) return *it;
    return *out.insert(it, Entry{j, 0, 1.0f, 1.0f});
  };
  if (rewritten)
    for (const auto& nb : *own_new) {
      auto& e = entry_of(nb.neighbor);
      e.flags = static_cast<std::uint8_t>(e.flags | kOwn | (nb.intact ? kOwnIntact : 0));
      e.factor = e.dilatation = 1.0f;  // set again by the interface correction
    }
  for (auto d = dual_first; d != dual_last; ++d) {
    auto& e = entry_of(d->owner);
    e.flags = static_cast<std::uint8_t>(e.flags | kDual | (d->intact ? kDualIntact : 0));
  }
}

/// Writes `entries` as row t (moving it to the end of the arena when it does not fit).
void write_row(BondRows& b, const ParticleStore& p, std::int32_t t,
               const std::vector<Entry>& entries, LengthInterner& lengths) {
  const auto u = static_cast<std::size_t>(t);
  const auto n = static_cast<std::int32_t>(entries.size());
  b.live += n - b.rows.count[u];
  b.own_bonds -= b.own_count(u);
  const std::int64_t old_start = b.rows.start[u], old_capacity = b.rows.capacity[u];
  const auto s = b.rows.make_room(u, n);
  b.fit_arena();
  if (s != old_start)  // the slots left behind are garbage: no bond, no particle
    for (auto k = old_start; k < old_start + old_capacity; ++k) b.other[k] = -1, b.flags[k] = 0;
  for (std::int32_t e = 0; e < n; ++e) {
    const auto k = s + e;
    const auto& x = entries[static_cast<std::size_t>(e)];
    b.other[k] = x.other;
    b.flags[k] = x.flags;
    b.length_index[k] =
        lengths.index_of(inverse_reference_length(p, u, static_cast<std::size_t>(x.other)));
    b.stiffness[k] = 0.0f;  // derived by the caller
    if (!b.factor.empty()) b.factor[k] = x.factor;
    if (!b.dilatation_factor.empty()) b.dilatation_factor[k] = x.dilatation;
    b.own_bonds += x.flags & kOwn ? 1 : 0;
  }
  for (auto k = s + n; k < s + b.rows.capacity[u]; ++k) b.other[k] = -1, b.flags[k] = 0;
  b.rows.count[u] = n;
}

}  // namespace

std::vector<std::int32_t> replace_own_bonds(BondRows& b, const ParticleStore& p,
                                            const std::vector<std::int32_t>& owners,
                                            const std::vector<std::vector<NewBond>>& bonds) {
  if (owners.size() != bonds.size())
    throw EngineError("replace_own_bonds: one list of new bonds per owner");
  // Rows that change: the owners, the rows holding their old bonds' dual side, and the rows that
  // receive the dual side of a new bond.
  std::vector<DualSide> dual_new;
  std::vector<std::int32_t> touched(owners);
  for (std::size_t k = 0; k < owners.size(); ++k) {
    const auto i = static_cast<std::size_t>(owners[k]);
    for (auto e = b.begin(i); e < b.end(i); ++e)
      if (b.flags[e] & kOwn) touched.push_back(b.other[e]);
    for (const auto& nb : bonds[k]) {
      dual_new.push_back({nb.neighbor, owners[k], nb.intact});
      touched.push_back(nb.neighbor);
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::sort(dual_new.begin(), dual_new.end(),
            [](const DualSide& a, const DualSide& b) { return a.key() < b.key(); });
  // Merge every touched row from the current rows first (each on its own, in parallel), then
  // write them all in order: a row's merge reads only its own entries, and the others' are not
  // needed.
  std::vector<std::vector<Entry>> merged(touched.size());
  const auto n = static_cast<std::int64_t>(touched.size());
#pragma omp parallel for schedule(dynamic, 64) if (n >= 256)
  for (std::int64_t r = 0; r < n; ++r) {
    const auto t = touched[r];
    const auto by_row = [](const DualSide& e, std::int32_t x) { return e.neighbour < x; };
    const auto d = std::lower_bound(dual_new.begin(), dual_new.end(), t, by_row);
    auto last = d;
    while (last != dual_new.end() && last->neighbour == t) ++last;
    const auto o = std::lower_bound(owners.begin(), owners.end(), t);
    const bool is_owner = o != owners.end() && *o == t;
    merge_row(b, t, owners,
              is_owner ? &bonds[static_cast<std::size_t>(o - owners.begin())] : nullptr,
              dual_new.data() + (d - dual_new.begin()), dual_new.data() + (last - dual_new.begin()),
              merged[static_cast<std::size_t>(r)]);
  }
  LengthInterner lengths(b.inverse_lengths);
  for (std::size_t r = 0; r < touched.size(); ++r) write_row(b, p, touched[r], merged[r], lengths);
  return touched;
}

}  // namespace dhpd
