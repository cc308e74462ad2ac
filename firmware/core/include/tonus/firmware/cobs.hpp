// Consistent Overhead Byte Stuffing (Cheshire & Baker, 1999): frames a message
// on a byte stream (the self-test's USART) with 0x00 as the only delimiter.
// An encoded frame is at most n + n/254 + 1 bytes, followed by one 0x00.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tonus::fw::cobs {

constexpr std::size_t max_encoded_size(std::size_t n) { return n + n / 254 + 1; }

// Encodes `in` into `out` (no trailing delimiter); returns the size, 0 if `out` is too small.
std::size_t encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out);
// Decodes one frame (without its delimiter); returns the size, 0 on a malformed frame or small `out`.
std::size_t decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out);

}  // namespace tonus::fw::cobs
