// Regrouping particles by time level with the fewest moves (engine/physics/time_levels.*,
// engine/discretization/bond_renumber.cpp, particles.cpp; docs/theory.md §19.3): the order sorts
// any levels and moves exactly the particles outside their level's block; the rows renumbered in
// place equal the packed renumbering row by row and report every row whose entries moved; the
// store permuted in place equals a gather.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/physics/time_levels.hpp"
#include "tests/support/bonds.hpp"
#include "tests/support/engine.hpp"

namespace dhpd {
namespace {

std::vector<std::int32_t> inverse(const std::vector<std::int32_t>& order) {
  std::vector<std::int32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
  return new_index;
}

/// Levels sorted, then `changes` particles given another level (what an event's re-levelling does).
std::vector<std::int8_t> nearly_sorted_levels(std::size_t n, int levels, int changes,
                                              std::mt19937& rng) {
  std::vector<std::int8_t> level(n);
  for (std::size_t k = 0; k < n; ++k) level[k] = static_cast<std::int8_t>(k * levels / n);
  for (int c = 0; c < changes; ++c) level[rng() % n] = static_cast<std::int8_t>(rng() % levels);
  return level;
}

TEST(Regroup, FewestMovesSortsByLevelAndMovesOnlyTheMisplaced) {
  std::mt19937 rng(7);
  for (const int levels : {1, 2, 3, 5})
    for (const int changes : {0, 1, 20, 400}) {
      const std::size_t n = 1000;
      const auto level = nearly_sorted_levels(n, levels, changes, rng);
      const auto order = fewest_moves_by_level(level);
      auto seen = order;
      std::sort(seen.begin(), seen.end());
      std::vector<std::int32_t> every(n);
      std::iota(every.begin(), every.end(), 0);
      ASSERT_EQ(seen, every) << "not a permutation";
      std::vector<std::int8_t> after(n);
      for (std::size_t k = 0; k < n; ++k) after[k] = level[static_cast<std::size_t>(order[k])];
      EXPECT_TRUE(std::is_sorted(after.begin(), after.end())) << levels << " " << changes;
      // Brute force: slot k is misplaced when its level is not that of the sorted levels there.
      auto sorted = level;
      std::sort(sorted.begin(), sorted.end());
      std::size_t misplaced = 0, moved = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const bool out = level[k] != sorted[k];
        const bool moves = order[k] != static_cast<std::int32_t>(k);
        misplaced += out ? 1 : 0;
        moved += moves ? 1 : 0;
        EXPECT_EQ(out, moves) << "slot " << k;
      }
      EXPECT_EQ(moved, misplaced);
      if (changes == 0) {
        EXPECT_EQ(moved, 0u);
      }
      if (changes == 1) {
        EXPECT_LE(moved, static_cast<std::size_t>(levels)) << "one change moves a chain of blocks";
      }
    }
}

TEST(Regroup, RowsRenumberedInPlaceEqualThePackedRenumberingRowByRow) {
  for (const int dim : {2, 3}) {
    const auto p = test::random_cloud(dim, 400, dim == 2 ? 0.02 : 0.07, 3.0, 3.015, 30 + dim);
    auto a = test::assemble(p, ForceModel::DualHorizon, PartialVolume::Linear,
                            Material{72e9, 2440, 3.8}, Section{dim});
    auto& b = a.bonds;
    std::mt19937 rng(11 + dim);
    test::break_some_and_scale(b, p.size(), rng);
    a.refresh(p);
    for (std::size_t i = 0; i < p.size(); ++i)  // one threshold per row, to see rows swap
      b.break_ratio2[i] = 1.0 + 1e-3 * static_cast<double>(i);
    for (const int changes : {1, 15, 200}) {
      const auto order = fewest_moves_by_level(nearly_sorted_levels(p.size(), 3, changes, rng));
      const auto new_index = inverse(order);
      std::vector<std::int32_t> moved;
      for (std::size_t k = 0; k < order.size(); ++k)
        if (order[k] != static_cast<std::int32_t>(k)) moved.push_back(static_cast<std::int32_t>(k));
      const auto packed = renumbered_rows(b, order, new_index);
      auto in_place = b;
      const auto rows = renumber_rows_in_place(in_place, order, new_index, moved);
      test::expect_consistent(in_place, p.size(), "in place");
      EXPECT_TRUE(std::is_sorted(rows.begin(), rows.end()));
      EXPECT_EQ(in_place.own_bonds, b.own_bonds);
      for (std::size_t i = 0; i < p.size(); ++i) {
        ASSERT_EQ(in_place.end(i) - in_place.begin(i), packed.end(i) - packed.begin(i));
        EXPECT_EQ(in_place.break_ratio2[i], packed.break_ratio2[i]);
        const bool reported = std::binary_search(rows.begin(), rows.end(), i);
        const auto old = static_cast<std::size_t>(order[i]);
        bool same_as_before = true;  // the entries of its particle's old row, in the same places
        for (auto t = 0; t < in_place.end(i) - in_place.begin(i); ++t) {
          const auto k = in_place.begin(i) + t, q = packed.begin(i) + t, o = b.begin(old) + t;
          EXPECT_EQ(in_place.other[k], packed.other[q]);
          EXPECT_EQ(in_place.inverse_length(k), packed.inverse_length(q));
          EXPECT_EQ(in_place.flags[k], packed.flags[q]);
          EXPECT_EQ(in_place.factor[k], packed.factor[q]);
          EXPECT_EQ(in_place.stiffness[k], packed.stiffness[q]);
          same_as_before = same_as_before && old == i && in_place.other[k] == b.other[o] &&
                           in_place.flags[k] == b.flags[o];
        }
        if (!same_as_before) {
          EXPECT_TRUE(reported) << dim << "D row " << i << " changed but is not reported";
        }
      }
      // Only the moved rows and their partners are touched: far fewer than all for one change.
      if (changes == 1) {
        EXPECT_LT(rows.size(), p.size() / 4) << dim << "D";
      }
    }
  }
}

TEST(Regroup, StorePermutedInPlaceEqualsAGather) {
  auto p = test::random_cloud(2, 300, 0.02, 3.0, 3.015, 5);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.velocity[0][i] = 0.5 * static_cast<double>(i);
    p.damage[i] = 1.0 / static_cast<double>(i + 1);
  }
  std::mt19937 rng(3);
  const auto order = fewest_moves_by_level(nearly_sorted_levels(p.size(), 2, 30, rng));
  std::vector<std::int32_t> moved;
  for (std::size_t k = 0; k < order.size(); ++k)
    if (order[k] != static_cast<std::int32_t>(k)) moved.push_back(static_cast<std::int32_t>(k));
  ASSERT_FALSE(moved.empty());
  auto gathered = gather(p, order);
  permute_slots(p, order, moved);
  auto a = p.fields(), g = gathered.fields();
  ASSERT_EQ(a.size(), g.size());
  for (std::size_t f = 0; f < a.size(); ++f) {
    const bool equal = std::visit(
        [&](auto* x) {
          using T = std::remove_pointer_t<decltype(x)>;
          return *x == *std::get<T*>(g[f].data);
        },
        a[f].data);
    EXPECT_TRUE(equal) << a[f].name;
  }
}

}  // namespace
}  // namespace dhpd
