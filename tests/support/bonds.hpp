// Consistency of a bond list and its dual lists, for from-scratch builds and after incremental
// edits (refinement events, re-sorts): every live bond sits in its owner's row and appears exactly
// once in its neighbour's dual row, and every dual entry names a live bond whose neighbour owns the
// row. Garbage slots (outside every live row) have owner and neighbour −1.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "engine/discretization/bonds.hpp"

namespace dhpd::test {

inline void expect_consistent(const BondList& b, const DualList& d, std::size_t particles,
                              const std::string& what = "") {
  ASSERT_EQ(b.particles(), particles) << what;
  ASSERT_EQ(d.rows.rows(), particles) << what;
  ASSERT_EQ(b.slots(), static_cast<std::size_t>(b.rows.arena)) << what;
  std::vector<std::uint8_t> live(b.slots(), 0);
  std::int64_t live_count = 0;
  std::size_t wrong_owner = 0, bad_neighbour = 0, repeated_neighbour = 0;
  for (std::size_t i = 0; i < particles; ++i) {
    std::vector<std::int32_t> seen;
    for (auto k = b.begin(i); k < b.end(i); ++k) {
      const auto s = static_cast<std::size_t>(k);
      live[s] = 1;
      ++live_count;
      wrong_owner += b.owner[s] != static_cast<std::int32_t>(i);
      const auto j = b.neighbor[s];
      bad_neighbour +=
          j < 0 || static_cast<std::size_t>(j) >= particles || static_cast<std::size_t>(j) == i;
      for (const auto other : seen) repeated_neighbour += other == j;
      seen.push_back(j);
    }
  }
  EXPECT_EQ(live_count, b.live) << what;
  EXPECT_EQ(wrong_owner, 0u) << what;
  EXPECT_EQ(bad_neighbour, 0u) << what;
  EXPECT_EQ(repeated_neighbour, 0u) << what << " (a pair bonded twice in one row)";
  std::size_t garbage_not_marked = 0;
  for (std::size_t s = 0; s < b.slots(); ++s)
    if (!live[s]) garbage_not_marked += b.owner[s] != -1 || b.neighbor[s] != -1;
  EXPECT_EQ(garbage_not_marked, 0u) << what;
  // Dual rows: each entry a live bond on the row's particle; each live bond exactly once.
  std::vector<int> times(b.slots(), 0);
  std::size_t dead_entry = 0, wrong_row = 0;
  for (std::size_t j = 0; j < particles; ++j)
    for (auto e = d.begin(j); e < d.end(j); ++e) {
      const auto bond = d.bond[static_cast<std::size_t>(e)];
      if (bond < 0 || static_cast<std::size_t>(bond) >= b.slots() ||
          !live[static_cast<std::size_t>(bond)]) {
        ++dead_entry;
        continue;
      }
      wrong_row += b.neighbor[static_cast<std::size_t>(bond)] != static_cast<std::int32_t>(j);
      ++times[static_cast<std::size_t>(bond)];
    }
  EXPECT_EQ(dead_entry, 0u) << what;
  EXPECT_EQ(wrong_row, 0u) << what;
  std::size_t not_once = 0;
  for (std::size_t s = 0; s < b.slots(); ++s)
    if (live[s]) not_once += times[s] != 1;
  EXPECT_EQ(not_once, 0u) << what << " (bonds missing from, or repeated in, a dual row)";
}

}  // namespace dhpd::test
