// The table of distinct bond lengths (engine/discretization/length_table.*; docs/theory.md §18):
// a lattice's rows hold a few hundred values however many bonds they have, every entry's value
// is the bits inverse_reference_length gives, the table is canonical (sorted, each value once,
// each used) after a build and a renumbering, edits reuse the values already there, and the
// canonical table does not depend on the order values were interned in.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/length_table.hpp"
#include "tests/support/bonds.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

/// Sorted strictly increasing, and every value used by some live entry.
void expect_canonical(const BondRows& b, const char* what) {
  EXPECT_TRUE(std::adjacent_find(b.inverse_lengths.begin(), b.inverse_lengths.end(),
                                 [](double x, double y) { return !(x < y); }) ==
              b.inverse_lengths.end())
      << what << ": not sorted, or a value twice";
  std::vector<char> used(b.inverse_lengths.size(), 0);
  for (std::size_t i = 0; i < b.particles(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      used[static_cast<std::size_t>(b.length_index[k])] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << what << ": a value no entry uses";
}

/// Every live entry's 1/|ξ| is the reference positions' (bit for bit).
void expect_reference_lengths(const BondRows& b, const ParticleStore& p, const char* what) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k)
      wrong += b.inverse_length(k) !=
               inverse_reference_length(p, i, static_cast<std::size_t>(b.other[k]));
  EXPECT_EQ(wrong, 0u) << what;
}

TEST(LengthTable, ALatticeHoldsAFewHundredValuesForAllItsBonds) {
  Section s;
  s.dim = 3;
  const auto p = test::lattice_store(3, 24, 1e-3, 3.015, s);
  const auto b = build_bond_rows(p, PartialVolume::Linear, {});
  // 122 neighbour offsets within 3.015 dx, 19 distinct |offset|²; round-off of the positions
  // splits each into a few bit patterns.
  EXPECT_GT(b.live, 1'000'000);
  EXPECT_GE(b.inverse_lengths.size(), 19u);
  EXPECT_LT(b.inverse_lengths.size(), 400u);
  expect_canonical(b, "lattice");
  expect_reference_lengths(b, p, "lattice");
}

TEST(LengthTable, RenumberingAndEditsKeepEveryValueAndTheTableCanonical) {
  const auto p = test::random_cloud(2, 800, 0.02, 3.0, 3.015, 5);
  auto b = build_bond_rows(p, PartialVolume::Linear, {});
  // An irregular cloud: about one value per pair.
  EXPECT_GT(b.inverse_lengths.size(), static_cast<std::size_t>(b.live) / 3);
  expect_canonical(b, "cloud");
  // Replacing bonds appends the values the table lacks and reuses the ones it has.
  std::vector<std::int32_t> owners;
  std::vector<std::vector<NewBond>> bonds;
  for (std::int32_t i = 0; i < 800; i += 9) {
    owners.push_back(i);
    bonds.emplace_back();
    for (auto k = b.begin(static_cast<std::size_t>(i)); k < b.end(static_cast<std::size_t>(i)); ++k)
      if (b.has_own(k)) bonds.back().push_back({b.other[k], true});
    bonds.back().push_back({(i + 401) % 800, true});  // a far neighbour: a length not yet held
  }
  std::set<double> held(b.inverse_lengths.begin(), b.inverse_lengths.end()), lacking;
  for (std::size_t r = 0; r < owners.size(); ++r) {
    const double v = inverse_reference_length(p, static_cast<std::size_t>(owners[r]),
                                              static_cast<std::size_t>(bonds[r].back().neighbor));
    if (!held.count(v)) lacking.insert(v);
  }
  EXPECT_GT(lacking.size(), owners.size() / 2);
  const auto before = b.inverse_lengths.size();
  replace_own_bonds(b, p, owners, bonds);
  EXPECT_EQ(b.inverse_lengths.size(), before + lacking.size()) << "one new value per new length";
  expect_reference_lengths(b, p, "after the replacement");
  test::expect_consistent(b, p.size(), "after the replacement", false);
  // Renumbering (compaction) makes the table canonical again.
  std::vector<std::int32_t> order(p.size()), new_index(p.size());
  std::iota(order.begin(), order.end(), 0);
  std::reverse(order.begin(), order.end());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
  const auto renumbered = renumbered_rows(b, order, new_index);
  expect_canonical(renumbered, "renumbered");
}

TEST(LengthTable, TheCanonicalTableDoesNotDependOnTheInterningOrder) {
  std::mt19937 rng(3);
  std::vector<double> values;
  for (int k = 0; k < 50; ++k) values.push_back(1.0 + rng() % 20);  // repeats on purpose
  auto canonical = [&](const std::vector<double>& order) {
    std::vector<double> table = {99.0};  // a value no entry uses: dropped
    LengthInterner in(table);
    std::vector<std::int32_t> index, other(order.size(), 0);
    for (const double v : order) index.push_back(in.index_of(v));
    other.push_back(-1), index.push_back(0);  // a garbage slot
    canonical_lengths(table, index, other);
    std::vector<double> per_entry;
    for (std::size_t k = 0; k + 1 < index.size(); ++k) per_entry.push_back(table[index[k]]);
    return std::make_pair(table, per_entry);
  };
  auto shuffled = values;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const auto [table_a, values_a] = canonical(values);
  const auto [table_b, values_b] = canonical(shuffled);
  EXPECT_EQ(table_a, table_b);
  EXPECT_EQ(values_a, values);
  EXPECT_EQ(values_b, shuffled);
  EXPECT_TRUE(std::is_sorted(table_a.begin(), table_a.end()));
  EXPECT_EQ(std::count(table_a.begin(), table_a.end(), 99.0), 0);
  std::vector<double> distinct = values;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_EQ(table_a, distinct);
}

}  // namespace
}  // namespace dhpd
