// LZ4 blocks of a checkpoint's payload (see payload_blocks.hpp).
#include "engine/checkpoint/payload_blocks.hpp"

#include <fmt/core.h>
#include <lz4.h>

#include <algorithm>
#include <cstring>

#include "engine/base/errors.hpp"

namespace dhpd::archive {
namespace {
constexpr std::size_t kBlockHeader = 2 * sizeof(std::uint32_t);
}  // namespace

BlockCompressor::BlockCompressor(std::function<void(std::span<const std::byte>)> sink)
    : sink_(std::move(sink)) {
  raw_.reserve(kPayloadBlock);
  stored_.resize(kBlockHeader + static_cast<std::size_t>(LZ4_compressBound(kPayloadBlock)));
}

void BlockCompressor::add(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const std::size_t take = std::min(bytes.size(), kPayloadBlock - raw_.size());
    raw_.insert(raw_.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(take));
    bytes = bytes.subspan(take);
    if (raw_.size() == kPayloadBlock) store_block();
  }
}

void BlockCompressor::finish() {
  if (!raw_.empty()) store_block();
}

void BlockCompressor::store_block() {
  const int n = LZ4_compress_default(reinterpret_cast<const char*>(raw_.data()),
                                     reinterpret_cast<char*>(stored_.data()) + kBlockHeader,
                                     static_cast<int>(raw_.size()),
                                     static_cast<int>(stored_.size() - kBlockHeader));
  if (n <= 0) throw IoError("LZ4 could not compress a block of a checkpoint");
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(raw_.size()),
                                  static_cast<std::uint32_t>(n)};
  std::memcpy(stored_.data(), sizes, kBlockHeader);
  sink_(std::span(stored_).first(kBlockHeader + static_cast<std::size_t>(n)));
  raw_.clear();
}

std::vector<std::byte> inflate_blocks(std::span<const std::byte> stored,
                                      const std::string& source) {
  const auto refuse = [&source](std::size_t at, const char* why) {
    throw InputError(fmt::format("{}: not a valid checkpoint: the block at payload byte {} {}",
                                 source, at, why));
  };
  std::vector<std::byte> out;
  for (std::size_t at = 0; at < stored.size();) {
    std::uint32_t sizes[2];
    if (stored.size() - at < kBlockHeader) refuse(at, "is cut short");
    std::memcpy(sizes, stored.data() + at, kBlockHeader);
    if (sizes[0] == 0 || sizes[0] > kPayloadBlock) refuse(at, "has an impossible size");
    if (sizes[1] > stored.size() - at - kBlockHeader) refuse(at, "is cut short");
    const std::size_t before = out.size();
    out.resize(before + sizes[0]);
    const int n =
        LZ4_decompress_safe(reinterpret_cast<const char*>(stored.data() + at + kBlockHeader),
                            reinterpret_cast<char*>(out.data() + before),
                            static_cast<int>(sizes[1]), static_cast<int>(sizes[0]));
    if (n != static_cast<int>(sizes[0])) refuse(at, "does not inflate to its size");
    at += kBlockHeader + sizes[1];
  }
  return out;
}

}  // namespace dhpd::archive
