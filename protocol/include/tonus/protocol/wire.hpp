// Little-endian, bounds-checked field-by-field serialisation.
//
// No struct punning: every field is written and read byte by byte, so the
// layout is the same on every compiler and CPU. Both classes are sticky: the
// first out-of-bounds access sets an error and every later access is a no-op,
// so a codec can write its fields straight through and check once at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/error.hpp"

namespace tonus::proto {

class ByteWriter {
 public:
  explicit constexpr ByteWriter(std::span<std::uint8_t> out) : out_(out) {}

  constexpr void u8(std::uint8_t v) {
    if (!reserve(1)) return;
    out_[pos_++] = v;
  }
  constexpr void u16(std::uint16_t v) {
    if (!reserve(2)) return;
    out_[pos_++] = static_cast<std::uint8_t>(v);
    out_[pos_++] = static_cast<std::uint8_t>(v >> 8U);
  }
  constexpr void u32(std::uint32_t v) {
    if (!reserve(4)) return;
    for (unsigned i = 0; i < 4; ++i) out_[pos_++] = static_cast<std::uint8_t>(v >> (8U * i));
  }
  constexpr void u64(std::uint64_t v) {
    if (!reserve(8)) return;
    for (unsigned i = 0; i < 8; ++i) out_[pos_++] = static_cast<std::uint8_t>(v >> (8U * i));
  }
  constexpr void bytes(std::span<const std::uint8_t> v) {
    if (!reserve(v.size())) return;
    for (std::uint8_t b : v) out_[pos_++] = b;
  }
  constexpr void zeros(std::size_t n) {
    if (!reserve(n)) return;
    for (std::size_t i = 0; i < n; ++i) out_[pos_++] = 0;
  }

  [[nodiscard]] constexpr std::size_t size() const { return pos_; }
  [[nodiscard]] constexpr bool ok() const { return !overflow_; }
  [[nodiscard]] constexpr Error error() const { return overflow_ ? Error::buffer_too_small : Error::ok; }
  [[nodiscard]] constexpr std::span<std::uint8_t> written() const { return out_.first(pos_); }

 private:
  constexpr bool reserve(std::size_t n) {
    if (overflow_ || out_.size() - pos_ < n) {
      overflow_ = true;
      return false;
    }
    return true;
  }

  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool overflow_ = false;
};

class ByteReader {
 public:
  explicit constexpr ByteReader(std::span<const std::uint8_t> in) : in_(in) {}

  constexpr std::uint8_t u8() {
    if (!take(1)) return 0;
    return in_[pos_++];
  }
  constexpr std::uint16_t u16() {
    if (!take(2)) return 0;
    auto v = static_cast<std::uint16_t>(in_[pos_] | (in_[pos_ + 1] << 8U));
    pos_ += 2;
    return v;
  }
  constexpr std::uint32_t u32() {
    if (!take(4)) return 0;
    std::uint32_t v = 0;
    for (unsigned i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(in_[pos_++]) << (8U * i);
    return v;
  }
  constexpr std::uint64_t u64() {
    if (!take(8)) return 0;
    std::uint64_t v = 0;
    for (unsigned i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(in_[pos_++]) << (8U * i);
    return v;
  }
  constexpr void bytes(std::span<std::uint8_t> out) {
    if (!take(out.size())) return;
    for (std::uint8_t& b : out) b = in_[pos_++];
  }
  constexpr void skip(std::size_t n) {
    if (take(n)) pos_ += n;
  }

  [[nodiscard]] constexpr std::size_t position() const { return pos_; }
  [[nodiscard]] constexpr std::size_t remaining() const { return in_.size() - pos_; }
  [[nodiscard]] constexpr bool ok() const { return !underflow_; }
  [[nodiscard]] constexpr Error error() const { return underflow_ ? Error::truncated : Error::ok; }

 private:
  constexpr bool take(std::size_t n) {
    if (underflow_ || in_.size() - pos_ < n) {
      underflow_ = true;
      return false;
    }
    return true;
  }

  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  bool underflow_ = false;
};

}  // namespace tonus::proto
