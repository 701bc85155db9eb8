// Per-particle rows in one flat arena: row i is [start[i], start[i] + count[i]) with room for
// capacity[i] entries. A row that outgrows its room moves to the end of the arena; the slots it
// leaves are garbage until the next compaction. From-scratch builds are plain CSR (no spare room).
#pragma once
#include <cstdint>
#include <vector>

namespace dhpd {

struct RowIndex {
  std::vector<std::int64_t> start;
  std::vector<std::int32_t> count, capacity;
  std::int64_t arena = 0;    ///< slots handed out so far (live, spare and garbage)
  std::int64_t garbage = 0;  ///< slots of rows that moved away (reclaimed only by compaction)

  std::size_t rows() const { return start.size(); }
  /// Bytes held by the index arrays (capacities).
  std::size_t bytes() const {
    return start.capacity() * sizeof(std::int64_t) +
           (count.capacity() + capacity.capacity()) * sizeof(std::int32_t);
  }
  std::int64_t begin(std::size_t i) const { return start[i]; }
  std::int64_t end(std::size_t i) const { return start[i] + count[i]; }

  /// CSR layout for the given row lengths: rows back to back, capacity = count.
  static RowIndex packed(const std::vector<std::int32_t>& counts) {
    RowIndex r;
    r.start.resize(counts.size());
    r.count = counts;
    r.capacity = counts;
    for (std::size_t i = 0; i < counts.size(); ++i) r.start[i] = r.arena, r.arena += counts[i];
    return r;
  }

  /// Appends empty rows up to n rows in total.
  void grow_rows(std::size_t n) {
    start.resize(n, arena);
    count.resize(n, 0);
    capacity.resize(n, 0);
  }

  /// Gives row i room for `n` entries and returns where they go. The row stays where it is when
  /// it fits; otherwise it moves to the end of the arena with 25 % spare room (entries are not
  /// copied: the caller rewrites the row, or copies the first count[i] itself before writing).
  /// The caller resizes its data arrays to `arena` afterwards. count[i] is left unchanged.
  std::int64_t make_room(std::size_t i, std::int32_t n) {
    if (n <= capacity[i]) return start[i];
    garbage += capacity[i];
    const std::int32_t room = n + n / 4 + 2;
    start[i] = arena;
    capacity[i] = room;
    arena += room;
    return start[i];
  }
};

}  // namespace dhpd
