// Systematic corruption helpers for decoder robustness tests.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace tonus::test {

// Calls fn with every variant of `bytes` that differs in exactly one byte
// (all 255 other values of each position).
template <class Fn>
void for_each_byte_corruption(std::span<const std::uint8_t> bytes, Fn&& fn) {
  std::vector<std::uint8_t> copy(bytes.begin(), bytes.end());
  for (std::size_t i = 0; i < copy.size(); ++i) {
    const std::uint8_t original = copy[i];
    for (unsigned v = 0; v < 256; ++v) {
      if (v == original) continue;
      copy[i] = static_cast<std::uint8_t>(v);
      fn(std::span<const std::uint8_t>(copy));
    }
    copy[i] = original;
  }
}

}  // namespace tonus::test
