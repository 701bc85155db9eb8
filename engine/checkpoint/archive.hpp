// A minimal binary archive for checkpoints: trivially copyable values as raw bytes, containers
// with their size first. One templated `ar(x)` call serves writing and reading, so a class lists
// its fields once. The reader checks every size against the bytes left before it allocates.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "engine/base/errors.hpp"

namespace dhpd::archive {

template <class T>
struct IsVector : std::false_type {};
template <class T, class A>
struct IsVector<std::vector<T, A>> : std::true_type {};
template <class T>
struct IsArray : std::false_type {};
template <class T, std::size_t N>
struct IsArray<std::array<T, N>> : std::true_type {};
template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};
template <class T>
struct IsPair : std::false_type {};
template <class A, class B>
struct IsPair<std::pair<A, B>> : std::true_type {};

/// Appends archived values to a byte buffer; a counting writer only adds up their size (to
/// reserve the buffer once before the real pass).
class Writer {
 public:
  explicit Writer(bool counting = false) : counting_(counting) {}
  /// A writer that hands every piece to `sink` instead of keeping it.
  explicit Writer(std::function<void(std::span<const std::byte>)> sink) : sink_(std::move(sink)) {}
  /// A writer that appends to `reuse` after clearing it, keeping its memory.
  explicit Writer(std::vector<std::byte>&& reuse) : bytes_(std::move(reuse)) { bytes_.clear(); }
  template <class T>
  void operator()(const T& v) {
    if constexpr (std::is_same_v<T, std::string>) {
      size(v.size());
      raw(v.data(), v.size());
    } else if constexpr (IsVector<T>::value) {
      size(v.size());
      if constexpr (std::is_trivially_copyable_v<typename T::value_type>)
        raw(v.data(), v.size() * sizeof(typename T::value_type));
      else
        for (const auto& e : v) (*this)(e);
    } else if constexpr (IsOptional<T>::value) {
      (*this)(static_cast<std::uint8_t>(v.has_value()));
      if (v) (*this)(*v);
    } else if constexpr (IsPair<T>::value) {
      (*this)(v.first);
      (*this)(v.second);
    } else if constexpr (IsArray<T>::value && !std::is_trivially_copyable_v<T>) {
      for (const auto& e : v) (*this)(e);
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "archive only trivially copyable values");
      raw(&v, sizeof(T));
    }
  }
  /// A block of bytes with its size first (read back by Reader::section without a copy).
  void section(std::span<const std::byte> b) {
    size(b.size());
    raw(b.data(), b.size());
  }
  /// Bytes as they are, without their size (a reader knows it from an earlier value).
  void raw_bytes(std::span<const std::byte> b) { raw(b.data(), b.size()); }
  std::vector<std::byte>& bytes() { return bytes_; }
  std::size_t size() const { return counting_ ? counted_ : bytes_.size(); }
  void reserve(std::size_t n) { bytes_.reserve(n); }

 private:
  void size(std::size_t n) { (*this)(static_cast<std::uint64_t>(n)); }
  void raw(const void* p, std::size_t n) {
    if (n == 0) return;
    if (counting_) {
      counted_ += n;
      return;
    }
    if (sink_) {
      sink_(std::span(static_cast<const std::byte*>(p), n));
      return;
    }
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, p, n);
  }
  std::function<void(std::span<const std::byte>)> sink_;
  bool counting_ = false;
  std::size_t counted_ = 0;
  std::vector<std::byte> bytes_;
};

/// Reads what Writer wrote; throws InputError naming `source` when the bytes run out.
class Reader {
 public:
  Reader(std::span<const std::byte> bytes, std::string source)
      : bytes_(bytes), source_(std::move(source)) {}

  template <class T>
  void operator()(T& v) {
    if constexpr (std::is_same_v<T, std::string>) {
      v.resize(size(1));
      raw(v.data(), v.size());
    } else if constexpr (IsVector<T>::value) {
      using E = typename T::value_type;
      if constexpr (std::is_trivially_copyable_v<E>) {
        v.resize(size(sizeof(E)));
        raw(v.data(), v.size() * sizeof(E));
      } else {
        v.resize(size(1));  // every archived element takes at least one byte
        for (auto& e : v) (*this)(e);
      }
    } else if constexpr (IsOptional<T>::value) {
      std::uint8_t has = 0;
      (*this)(has);
      if (has > 1) fail("a flag is neither 0 nor 1");
      v.reset();
      if (has) (*this)(v.emplace());
    } else if constexpr (IsPair<T>::value) {
      (*this)(v.first);
      (*this)(v.second);
    } else if constexpr (IsArray<T>::value && !std::is_trivially_copyable_v<T>) {
      for (auto& e : v) (*this)(e);
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "archive only trivially copyable values");
      raw(&v, sizeof(T));
    }
  }
  /// What Writer::section wrote: a view into the bytes.
  std::span<const std::byte> section() {
    const std::size_t n = size(1);
    const auto s = bytes_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  const std::string& source() const { return source_; }
  [[noreturn]] void fail(const std::string& what) const;

 private:
  /// A count of elements of at least `element_bytes` each, bounded by the bytes left.
  std::size_t size(std::size_t element_bytes) {
    std::uint64_t n = 0;
    (*this)(n);
    if (n > remaining() / element_bytes) fail("a size is larger than the rest of the file");
    return static_cast<std::size_t>(n);
  }
  void raw(void* p, std::size_t n) {
    if (n > remaining()) fail("the data ends early");
    if (n > 0) std::memcpy(p, bytes_.data() + pos_, n);
    pos_ += n;
  }
  std::span<const std::byte> bytes_;
  std::size_t pos_ = 0;
  std::string source_;
};

/// A 64-bit FNV-1a hash taken over 8-byte words in the machine's byte order (then the tail bytes),
/// fed in pieces; detects truncated and corrupted checkpoints at memory speed.
class Checksum {
 public:
  void add(std::span<const std::byte> bytes);
  std::uint64_t value() const;

 private:
  std::uint64_t h_ = 14695981039346656037ull;
  std::array<std::byte, 8> pending_{};
  std::size_t pending_size_ = 0;
};

std::uint64_t checksum(std::span<const std::byte> bytes);

}  // namespace dhpd::archive
