// Renumbering the bond rows with the particles (docs/theory.md §18, §19.3): a compaction packs
// every row anew in the new order; a regrouping by time level moves a few rows in place.
#include <algorithm>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/length_table.hpp"

namespace dhpd {

namespace {

/// Capacity for `entries` entries in every entry array of `b`, the factor arrays when asked.
void reserve_entries(BondRows& b, std::size_t entries, bool factors, bool dilatation) {
  b.other.reserve(entries);
  b.length_index.reserve(entries);
  b.flags.reserve(entries);
  b.stiffness.reserve(entries);
  if (factors) b.factor.reserve(entries);
  if (dilatation) b.dilatation_factor.reserve(entries);
}

}  // namespace

BondRows renumbered_rows(const BondRows& rows, const std::vector<std::int32_t>& order,
                         const std::vector<std::int32_t>& new_index, double spare) {
  const std::size_t n = order.size();
  BondRows b;
  std::vector<std::int32_t> counts(n);
  for (std::size_t k = 0; k < n; ++k) counts[k] = rows.rows.count[order[k]];
  b.rows = RowIndex::packed(counts);
  const bool factors = !rows.factor.empty(), dilatation = !rows.dilatation_factor.empty();
  const auto arena = static_cast<std::size_t>(b.rows.arena);
  reserve_entries(b, arena + static_cast<std::size_t>(spare * static_cast<double>(arena)), factors,
                  dilatation);
  b.stiffness_scale = rows.stiffness_scale;
  b.break_ratio2.resize(n);
  b.live = b.rows.arena;
  b.own_bonds = rows.own_bonds;
  std::vector<std::pair<std::int32_t, std::int64_t>> row;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(order[k]);
    b.break_ratio2[k] = rows.break_ratio2[i];
    row.clear();
    for (auto e = rows.begin(i); e < rows.end(i); ++e)
      row.emplace_back(new_index[static_cast<std::size_t>(rows.other[e])], e);
    // Neighbours keep most of their order under a renumbering (Morton order within levels): an
    // insertion sort is about linear here (the new indices are distinct, so the order is unique).
    for (std::size_t a = 1; a < row.size(); ++a)
      for (std::size_t c = a; c > 0 && row[c].first < row[c - 1].first; --c)
        std::swap(row[c], row[c - 1]);
    // Packed rows follow each other: appending writes row k at its start, each entry once.
    for (const auto& [j, e] : row) {
      b.other.push_back(j);
      b.length_index.push_back(rows.length_index[e]);
      b.flags.push_back(rows.flags[e]);
      b.stiffness.push_back(rows.stiffness[e]);
      if (factors) b.factor.push_back(rows.factor[e]);
      if (dilatation) b.dilatation_factor.push_back(rows.dilatation_factor[e]);
    }
  }
  b.inverse_lengths = rows.inverse_lengths;
  canonical_lengths(b.inverse_lengths, b.length_index, b.other);
  return b;
}

namespace {

/// Sorts the entries of row i by `other` with every per-entry array (an insertion sort: a row
/// whose neighbours were renumbered in place is sorted but for a few entries).
void resort_row(BondRows& b, std::size_t i, std::vector<std::int64_t>& order) {
  const auto s = b.begin(i), n = b.end(i) - s;
  order.resize(static_cast<std::size_t>(n));
  for (std::int64_t t = 0; t < n; ++t) order[static_cast<std::size_t>(t)] = s + t;
  bool sorted = true;
  for (std::size_t a = 1; a < order.size(); ++a)
    for (std::size_t c = a; c > 0 && b.other[order[c]] < b.other[order[c - 1]]; --c)
      std::swap(order[c], order[c - 1]), sorted = false;
  if (sorted) return;
  const auto apply = [&](auto& values) {
    if (values.empty()) return;
    using V = typename std::decay_t<decltype(values)>::value_type;
    std::vector<V> row(order.size());
    for (std::size_t t = 0; t < order.size(); ++t) row[t] = values[order[t]];
    std::copy(row.begin(), row.end(), values.begin() + s);
  };
  apply(b.other), apply(b.length_index), apply(b.flags), apply(b.stiffness), apply(b.factor),
      apply(b.dilatation_factor);
}

}  // namespace

std::vector<std::int32_t> renumber_rows_in_place(BondRows& rows,
                                                 const std::vector<std::int32_t>& order,
                                                 const std::vector<std::int32_t>& new_index,
                                                 const std::vector<std::int32_t>& moved) {
  auto& r = rows.rows;
  move_slots(r.start, order, moved), move_slots(r.count, order, moved);
  move_slots(r.capacity, order, moved), move_slots(rows.break_ratio2, order, moved);
  // Rows list their partners both ways, so the rows naming a moved particle are its partners'.
  std::vector<std::int32_t> touched(moved);
  for (const auto k : moved)
    for (auto e = rows.begin(static_cast<std::size_t>(k));
         e < rows.end(static_cast<std::size_t>(k)); ++e)
      touched.push_back(new_index[static_cast<std::size_t>(rows.other[e])]);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::vector<std::int64_t> sort_order;
  for (const auto i : touched) {
    const auto u = static_cast<std::size_t>(i);
    for (auto e = rows.begin(u); e < rows.end(u); ++e)
      rows.other[e] = new_index[static_cast<std::size_t>(rows.other[e])];
    resort_row(rows, u, sort_order);
  }
  return touched;
}

}  // namespace dhpd
