// The table of distinct bond lengths (docs/theory.md §18).
#include "engine/discretization/length_table.hpp"

#include <algorithm>
#include <cstring>

#include "engine/base/errors.hpp"
#include "engine/base/parallel.hpp"

namespace dhpd {

namespace {
std::uint64_t bits_of(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}
}  // namespace

namespace {
/// No value has these bits (a negative NaN; lengths are positive and finite).
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
}  // namespace

LengthInterner::LengthInterner(std::vector<double>& table)
    : table_(table), keys_(1024, kEmpty), index_(1024, 0) {
  if (table.size() > kSeedLimit) return;
  for (std::size_t k = 0; k < table.size(); ++k) {
    const auto bits = bits_of(table[k]);
    const auto s = slot_of(bits);
    if (keys_[s] == kEmpty) insert(s, bits, static_cast<std::int32_t>(k));  // else a repeat
  }
}

void LengthInterner::insert(std::size_t slot, std::uint64_t bits, std::int32_t index) {
  keys_[slot] = bits, index_[slot] = index;
  if (2 * ++used_ > keys_.size()) grow();
}

std::size_t LengthInterner::slot_of(std::uint64_t bits) const {
  const std::size_t mask = keys_.size() - 1;
  std::size_t s = static_cast<std::size_t>((bits * 0x9E3779B97F4A7C15ull) >> 20) & mask;
  while (keys_[s] != kEmpty && keys_[s] != bits) s = (s + 1) & mask;
  return s;
}

void LengthInterner::grow() {
  std::vector<std::uint64_t> keys(2 * keys_.size(), kEmpty);
  std::vector<std::int32_t> index(keys.size(), 0);
  keys_.swap(keys), index_.swap(index);
  for (std::size_t s = 0; s < keys.size(); ++s)
    if (keys[s] != kEmpty) {
      const auto t = slot_of(keys[s]);
      keys_[t] = keys[s], index_[t] = index[s];
    }
}

std::int32_t LengthInterner::index_of(double inverse_length) {
  const auto bits = bits_of(inverse_length);
  const auto s = slot_of(bits);
  if (keys_[s] == bits) return index_[s];
  if (table_.size() >= static_cast<std::size_t>(INT32_MAX))
    throw EngineError("more than 2^31 distinct bond lengths");
  const auto index = static_cast<std::int32_t>(table_.size());
  table_.push_back(inverse_length);
  insert(s, bits, index);
  return index;
}

void canonical_lengths(std::vector<double>& table, std::vector<std::int32_t>& index,
                       const std::vector<std::int32_t>& other) {
  const auto slots = static_cast<std::int64_t>(index.size());
  std::vector<std::uint8_t> used(table.size(), 0);
  for (std::int64_t k = 0; k < slots; ++k)
    if (other[k] >= 0) used[static_cast<std::size_t>(index[k])] = 1;
  std::vector<double> values;
  for (std::size_t t = 0; t < table.size(); ++t)
    if (used[t]) values.push_back(table[t]);
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  std::vector<std::int32_t> remap(table.size(), 0);
  for (std::size_t t = 0; t < table.size(); ++t)
    if (used[t])
      remap[t] = static_cast<std::int32_t>(
          std::lower_bound(values.begin(), values.end(), table[t]) - values.begin());
#pragma omp parallel for schedule(static) if (slots >= 64 * kParallelMinParticles)
  for (std::int64_t k = 0; k < slots; ++k)
    index[k] = other[k] >= 0 ? remap[static_cast<std::size_t>(index[k])] : 0;
  values.shrink_to_fit();
  table = std::move(values);
}

}  // namespace dhpd
