// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no xorout).
// Check value: crc16("123456789") == 0x29B1. Guards command and response
// messages end to end, across CAN segmentation and recorded logs.
#pragma once

#include <cstdint>
#include <span>

namespace tonus::proto {

constexpr std::uint16_t crc16_ccitt(std::span<const std::uint8_t> data, std::uint16_t crc = 0xFFFF) {
  for (std::uint8_t byte : data) {
    // Shifts on unsigned int: uint16_t would promote to int (a sign conversion
    // that -Wsign-conversion reports under -fsanitize=undefined).
    crc = static_cast<std::uint16_t>(crc ^ (static_cast<unsigned>(byte) << 8U));
    for (int bit = 0; bit < 8; ++bit) {
      const unsigned wide = crc;
      crc = (wide & 0x8000U) != 0 ? static_cast<std::uint16_t>((wide << 1U) ^ 0x1021U)
                                  : static_cast<std::uint16_t>(wide << 1U);
    }
  }
  return crc;
}

}  // namespace tonus::proto
