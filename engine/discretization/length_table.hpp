// The distinct reference lengths of a run's bonds, each stored once (docs/theory.md §18): a row
// entry holds the index of its 1/|ξ| in the table instead of the value. A lattice has a few
// hundred distinct lengths however large it is (204 in a 100³ cube at m = 3.015), so an entry
// costs 4 bytes instead of 8; an irregular point set has about one value per pair, which costs
// what a value per entry did. The values are the bits inverse_reference_length gives: the
// physics does not change by a bit.
#pragma once
#include <cstdint>
#include <vector>

namespace dhpd {

/// Gives values their index in a table, adding the values the table lacks. One interner per
/// thread (it writes the table). A table of at most kSeedLimit values is indexed first, so a
/// lattice's table never repeats a value; a larger one is only appended to, and duplicates
/// wait for canonical_lengths. An open-addressing table of the values' bits (a build looks up
/// every entry: a node-based map took 1 % of the default scene's run).
class LengthInterner {
 public:
  static constexpr std::size_t kSeedLimit = std::size_t{1} << 16;

  explicit LengthInterner(std::vector<double>& table);
  std::int32_t index_of(double inverse_length);

 private:
  /// Slot of `bits`: where it is, or the empty slot where it goes.
  std::size_t slot_of(std::uint64_t bits) const;
  /// Puts `bits` with `index` into the empty `slot`, growing the slots past half full.
  void insert(std::size_t slot, std::uint64_t bits, std::int32_t index);
  void grow();

  std::vector<double>& table_;
  std::vector<std::uint64_t> keys_;  ///< bits of the value in each slot (kEmpty: none)
  std::vector<std::int32_t> index_;  ///< its index in the table
  std::size_t used_ = 0;
};

/// Makes `table` canonical: the values that live entries (other[k] ≥ 0) use, each once, in
/// increasing order; every live entry's index rewritten to match and every other slot's set to
/// 0. The result depends only on the entries' values, not on the order they were interned in
/// (so not on the thread count). In parallel over the entries.
void canonical_lengths(std::vector<double>& table, std::vector<std::int32_t>& index,
                       const std::vector<std::int32_t>& other);

}  // namespace dhpd
