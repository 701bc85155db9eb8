// The row arena (engine/discretization/row_arena.hpp): `packed` lays rows back to back with no
// spare room; `make_room` keeps a row that fits where it is and moves one that does not to the end
// of the arena with 25 % (+ 2) spare, counting the room it leaves as garbage; `grow_rows` appends
// empty rows. After any sequence of edits the rows never overlap, lie inside the arena, and live +
// spare + garbage slots add up to the arena.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "engine/discretization/row_arena.hpp"

namespace dhpd {
namespace {

/// The invariants of any RowIndex: count <= capacity, rows inside [0, arena), no two rows'
/// rooms overlap, and the sum of the rooms plus the garbage is the arena.
void expect_invariants(const RowIndex& r) {
  ASSERT_EQ(r.count.size(), r.rows());
  ASSERT_EQ(r.capacity.size(), r.rows());
  std::vector<std::pair<std::int64_t, std::int64_t>> rooms;  // [start, start + capacity)
  std::int64_t held = 0;
  for (std::size_t i = 0; i < r.rows(); ++i) {
    EXPECT_GE(r.count[i], 0) << i;
    EXPECT_LE(r.count[i], r.capacity[i]) << i;
    EXPECT_GE(r.start[i], 0) << i;
    EXPECT_LE(r.start[i] + r.capacity[i], r.arena) << i;
    EXPECT_EQ(r.end(i) - r.begin(i), r.count[i]) << i;
    if (r.capacity[i] > 0) rooms.emplace_back(r.start[i], r.start[i] + r.capacity[i]);
    held += r.capacity[i];
  }
  std::sort(rooms.begin(), rooms.end());
  for (std::size_t k = 1; k < rooms.size(); ++k)
    EXPECT_LE(rooms[k - 1].second, rooms[k].first) << "rooms overlap at slot " << rooms[k].first;
  EXPECT_EQ(held + r.garbage, r.arena);
}

TEST(RowArena, PackedIsCsrWithoutSpareRoom) {
  const std::vector<std::int32_t> counts{3, 0, 5, 1, 0, 2};
  const auto r = RowIndex::packed(counts);
  EXPECT_EQ(r.rows(), 6u);
  EXPECT_EQ(r.start, (std::vector<std::int64_t>{0, 3, 3, 8, 9, 9}));
  EXPECT_EQ(r.count, counts);
  EXPECT_EQ(r.capacity, counts);
  EXPECT_EQ(r.arena, 11);
  EXPECT_EQ(r.garbage, 0);
  EXPECT_EQ(r.begin(2), 3);
  EXPECT_EQ(r.end(2), 8);
  expect_invariants(r);
  const auto empty = RowIndex::packed({});
  EXPECT_EQ(empty.rows(), 0u);
  EXPECT_EQ(empty.arena, 0);
}

TEST(RowArena, MakeRoomKeepsARowThatFitsAndMovesOneThatDoesNot) {
  auto r = RowIndex::packed({3, 4, 2});  // arena 9
  // Fits (n <= capacity): the row stays, nothing else changes.
  EXPECT_EQ(r.make_room(1, 4), 3);
  EXPECT_EQ(r.make_room(1, 0), 3);
  EXPECT_EQ(r.arena, 9);
  EXPECT_EQ(r.garbage, 0);
  // Outgrows its room: moves to the end with room n + n/4 + 2 = 5 + 1 + 2 = 8; its old 4 slots
  // become garbage; count is the caller's to set.
  EXPECT_EQ(r.make_room(1, 5), 9);
  EXPECT_EQ(r.start[1], 9);
  EXPECT_EQ(r.capacity[1], 8);
  EXPECT_EQ(r.count[1], 4);
  EXPECT_EQ(r.arena, 17);
  EXPECT_EQ(r.garbage, 4);
  expect_invariants(r);
  // Within its new room it stays put, however often it is asked.
  EXPECT_EQ(r.make_room(1, 8), 9);
  EXPECT_EQ(r.arena, 17);
  // Past it, it moves again: room 20 + 5 + 2 = 27, garbage 4 + 8.
  EXPECT_EQ(r.make_room(1, 20), 17);
  EXPECT_EQ(r.capacity[1], 27);
  EXPECT_EQ(r.arena, 44);
  EXPECT_EQ(r.garbage, 12);
  // The other rows never moved.
  EXPECT_EQ(r.start[0], 0);
  EXPECT_EQ(r.start[2], 7);
  r.count[1] = 20;
  expect_invariants(r);
}

TEST(RowArena, GrowRowsAppendsEmptyRowsAtTheEndOfTheArena) {
  auto r = RowIndex::packed({2, 1});
  r.grow_rows(5);
  EXPECT_EQ(r.rows(), 5u);
  for (std::size_t i = 2; i < 5; ++i) {
    EXPECT_EQ(r.start[i], 3);
    EXPECT_EQ(r.count[i], 0);
    EXPECT_EQ(r.capacity[i], 0);
    EXPECT_EQ(r.begin(i), r.end(i));
  }
  EXPECT_EQ(r.arena, 3);
  expect_invariants(r);
  // An empty row that gets entries takes fresh room at the end; it leaves no garbage.
  EXPECT_EQ(r.make_room(3, 1), 3);
  EXPECT_EQ(r.capacity[3], 1 + 0 + 2);
  EXPECT_EQ(r.garbage, 0);
  EXPECT_EQ(r.arena, 6);
  r.grow_rows(5);  // no-op
  EXPECT_EQ(r.rows(), 5u);
  EXPECT_EQ(r.start[4], 3);
  expect_invariants(r);
}

TEST(RowArena, RandomEditsKeepEveryRowsEntriesAndTheInvariants) {
  // A data array that follows the arena the way the bond and dual lists use it: make room, copy
  // the row when it moved, append. Every row must read back exactly what was put into it.
  std::mt19937 rng(5);
  std::vector<std::vector<int>> expected(40);
  std::vector<std::int32_t> counts(40);
  for (std::size_t i = 0; i < 40; ++i) {
    counts[i] = static_cast<std::int32_t>(rng() % 6);
    for (int k = 0; k < counts[i]; ++k) expected[i].push_back(static_cast<int>(1000 * i + k));
  }
  auto r = RowIndex::packed(counts);
  std::vector<int> data;
  for (std::size_t i = 0; i < 40; ++i)
    data.insert(data.end(), expected[i].begin(), expected[i].end());
  ASSERT_EQ(static_cast<std::int64_t>(data.size()), r.arena);
  std::int64_t moves = 0;
  for (int edit = 0; edit < 2000; ++edit) {
    if (edit % 250 == 0) {  // new rows now and then
      const std::size_t n = r.rows() + 3;
      r.grow_rows(n);
      expected.resize(n);
    }
    const std::size_t i = rng() % r.rows();
    const int add = static_cast<int>(rng() % 4);
    const std::int64_t old_start = r.start[i], old_garbage = r.garbage;
    const std::int32_t old_capacity = r.capacity[i];
    const std::int64_t at = r.make_room(i, r.count[i] + add);
    data.resize(static_cast<std::size_t>(r.arena), -1);
    if (at != old_start) {  // moved: garbage grows by the room it left
      ++moves;
      EXPECT_EQ(r.garbage, old_garbage + old_capacity);
      std::copy_n(data.begin() + old_start, r.count[i], data.begin() + at);
    } else {
      EXPECT_EQ(r.garbage, old_garbage);
    }
    for (int k = 0; k < add; ++k) {
      const int value = static_cast<int>(1000 * i) + static_cast<int>(expected[i].size());
      data[static_cast<std::size_t>(r.end(i))] = value;
      ++r.count[i];
      expected[i].push_back(value);
    }
  }
  EXPECT_GT(moves, 50);
  expect_invariants(r);
  for (std::size_t i = 0; i < r.rows(); ++i) {
    const std::vector<int> row(data.begin() + r.begin(i), data.begin() + r.end(i));
    EXPECT_EQ(row, expected[i]) << "row " << i;
  }
  const std::int64_t live = std::accumulate(r.count.begin(), r.count.end(), std::int64_t{0});
  EXPECT_LE(live + r.garbage, r.arena);
}

}  // namespace
}  // namespace dhpd
