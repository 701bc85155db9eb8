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

LengthInterner::LengthInterner(std::vector<double>& table) : table_(table) {
  if (table.size() > kSeedLimit) return;
  for (std::size_t k = 0; k < table.size(); ++k)
    where_.emplace(bits_of(table[k]), static_cast<std::int32_t>(k));
}

std::int32_t LengthInterner::index_of(double inverse_length) {
  const auto [it, added] =
      where_.emplace(bits_of(inverse_length), static_cast<std::int32_t>(table_.size()));
  if (added) {
    if (table_.size() >= static_cast<std::size_t>(INT32_MAX))
      throw EngineError("more than 2^31 distinct bond lengths");
    table_.push_back(inverse_length);
  }
  return it->second;
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
