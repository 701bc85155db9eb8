// Consistency of bond rows, for from-scratch builds and after incremental edits (refinement
// events, re-sorts): every live row is sorted by its other particle with no repeat; every entry
// holds a bond; the own bond of row i's entry j is the dual bond of row j's entry i, with the same
// intact state, the same 1/|ξ| (an index into the length table) and (dual-horizon) the same pair
// stiffness; the counters agree; garbage slots (outside every live row) hold no particle and no
// bond.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "engine/discretization/bonds.hpp"

namespace dhpd::test {

inline void expect_consistent(const BondRows& b, std::size_t particles,
                              const std::string& what = "", bool pair_stiffness = true) {
  ASSERT_EQ(b.particles(), particles) << what;
  ASSERT_EQ(b.other.size(), static_cast<std::size_t>(b.rows.arena)) << what;
  ASSERT_EQ(b.break_ratio2.size(), particles) << what;
  ASSERT_EQ(b.length_index.size(), b.other.size()) << what;
  std::vector<std::uint8_t> live(b.other.size(), 0);
  std::int64_t live_count = 0, own_count = 0;
  std::size_t bad_other = 0, unsorted = 0, empty = 0, intact_without_bond = 0;
  std::size_t unpaired = 0, state_differs = 0, length_differs = 0, stiffness_differs = 0;
  for (std::size_t i = 0; i < particles; ++i)
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      const auto s = static_cast<std::size_t>(k);
      live[s] = 1;
      ASSERT_GE(b.length_index[s], 0) << what;
      ASSERT_LT(static_cast<std::size_t>(b.length_index[s]), b.inverse_lengths.size()) << what;
      ++live_count;
      own_count += b.has_own(k) ? 1 : 0;
      const auto j = b.other[s];
      if (j < 0 || static_cast<std::size_t>(j) >= particles || static_cast<std::size_t>(j) == i) {
        ++bad_other;
        continue;
      }
      unsorted += k > b.begin(i) && b.other[s - 1] >= j;
      empty += !(b.has_own(k) || b.has_dual(k));
      intact_without_bond +=
          (b.own_intact(k) && !b.has_own(k)) + (b.dual_intact(k) && !b.has_dual(k));
      const auto m = b.find(static_cast<std::size_t>(j), static_cast<std::int32_t>(i));
      if (m < 0 || b.has_own(k) != b.has_dual(m) || b.has_dual(k) != b.has_own(m)) {
        ++unpaired;
        continue;
      }
      state_differs += (b.has_own(k) && b.own_intact(k) != b.dual_intact(m)) +
                       (b.has_dual(k) && b.dual_intact(k) != b.own_intact(m));
      length_differs += b.inverse_length(k) != b.inverse_length(m);
      stiffness_differs +=
          pair_stiffness && b.stiffness[s] != b.stiffness[static_cast<std::size_t>(m)];
    }
  EXPECT_EQ(live_count, b.live) << what;
  EXPECT_EQ(own_count, b.own_bonds) << what;
  EXPECT_EQ(bad_other, 0u) << what;
  EXPECT_EQ(unsorted, 0u) << what << " (a row out of order, or a pair twice in one row)";
  EXPECT_EQ(empty, 0u) << what << " (an entry with no bond)";
  EXPECT_EQ(intact_without_bond, 0u) << what;
  EXPECT_EQ(unpaired, 0u) << what << " (an own bond without its dual side, or the reverse)";
  EXPECT_EQ(state_differs, 0u) << what << " (the two rows of a bond disagree on its state)";
  EXPECT_EQ(length_differs, 0u) << what;
  EXPECT_EQ(stiffness_differs, 0u) << what << " (the two rows of a pair differ in stiffness)";
  std::size_t garbage_not_marked = 0;
  for (std::size_t s = 0; s < b.other.size(); ++s)
    if (!live[s]) garbage_not_marked += b.other[s] != -1 || b.flags[s] != 0;
  EXPECT_EQ(garbage_not_marked, 0u) << what;
}

/// State a renumbering must carry: a factor on every own bond (as level interfaces get) and
/// about one bond in five broken, on both sides of its pair.
inline void break_some_and_scale(BondRows& b, std::size_t particles, std::mt19937& rng) {
  b.factor.assign(b.other.size(), 1.0f);
  for (std::size_t i = 0; i < particles; ++i)
    for_each_own_bond(b, i, [&](std::int64_t k, std::size_t j) {
      b.factor[k] = 1.0f + 0.01f * static_cast<float>(rng() % 50);
      if (rng() % 5) return;
      b.flags[k] &= static_cast<std::uint8_t>(~kOwnIntact);
      b.flags[b.find(j, static_cast<std::int32_t>(i))] &= static_cast<std::uint8_t>(~kDualIntact);
    });
}

}  // namespace dhpd::test
