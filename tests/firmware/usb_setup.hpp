// An 8-byte USB SETUP packet (USB 2.0 table 9-2), little-endian, as a host sends it.
#pragma once

#include <array>
#include <cstdint>

namespace tonus::test {

inline std::array<std::uint8_t, 8> setup_packet(std::uint8_t type, std::uint8_t request, std::uint16_t value,
                                                std::uint16_t index, std::uint16_t length = 0) {
  return {type,
          request,
          static_cast<std::uint8_t>(value),
          static_cast<std::uint8_t>(value >> 8U),
          static_cast<std::uint8_t>(index),
          static_cast<std::uint8_t>(index >> 8U),
          static_cast<std::uint8_t>(length),
          static_cast<std::uint8_t>(length >> 8U)};
}

}  // namespace tonus::test
