#include "tonus/firmware/cobs.hpp"

namespace tonus::fw::cobs {

std::size_t encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
  if (out.size() < max_encoded_size(in.size())) return 0;
  std::size_t code_at = 0;
  std::size_t w = 1;
  std::uint8_t code = 1;
  for (std::uint8_t b : in) {
    if (b != 0) {
      out[w++] = b;
      ++code;
    }
    if (b == 0 || code == 0xFF) {
      out[code_at] = code;
      code = 1;
      code_at = w++;
    }
  }
  out[code_at] = code;
  return w;
}

std::size_t decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
  std::size_t r = 0;
  std::size_t w = 0;
  while (r < in.size()) {
    const std::uint8_t code = in[r++];
    if (code == 0) return 0;
    for (std::uint8_t k = 1; k < code; ++k) {
      if (r >= in.size() || in[r] == 0 || w >= out.size()) return 0;
      out[w++] = in[r++];
    }
    if (code != 0xFF && r < in.size()) {
      if (w >= out.size()) return 0;
      out[w++] = 0;
    }
  }
  return w;
}

}  // namespace tonus::fw::cobs
