// Stiffness stream message (device -> host), sent at the report rate (<= 1 kHz).
//
// Layout (little-endian), see docs/protocol.md for the byte table:
//   0 u8 version | 1 u8 group_count | 2 u8 channel_count | 3 u8 boot_epoch
//   4 u16 sequence | 6 u32 device_time_us | 10 u16 status
//   12 u16 electrode_off | 14 u16 saturation | 16 u16 artifact
//   18 u16 level[group_count] | ... u16 envelope[channel_count]
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/error.hpp"
#include "tonus/protocol/limits.hpp"

namespace tonus::proto {

// Bits of StreamMessage::status. Unknown bits are ignored by decoders.
namespace status_bit {
inline constexpr std::uint16_t calibrated = 1U << 0U;      // a valid calibration is in use
inline constexpr std::uint16_t calibrating = 1U << 1U;     // a calibration phase is running
inline constexpr std::uint16_t watchdog_reset = 1U << 2U;  // last restart was by the watchdog
inline constexpr std::uint16_t config_dirty = 1U << 3U;    // RAM config differs from NVM
inline constexpr std::uint16_t block_lost = 1U << 4U;      // a sample block was lost since the last report
inline constexpr std::uint16_t known_mask = 0x001F;
// Bit 15 is the CAN binding's (can::kStatusEnvelopesFollow), never a device status.
}  // namespace status_bit

inline constexpr std::size_t kStreamHeaderSize = 18;
inline constexpr std::uint16_t kLevelMax = 0xFFFF;     // maximal co-contraction
inline constexpr std::uint16_t kEnvelopeOne = 0x8000;  // envelope == reference (MVC when calibrated)

// boot_epoch 0: the sender does not say (a version-1.0 device, or a binding
// without room for it, such as CAN).
inline constexpr std::uint8_t kBootEpochUnknown = 0;

struct StreamMessage {
  std::uint16_t sequence = 0;                           // +1 per report, wraps at 2^16
  std::uint32_t device_time_us = 0;                     // device monotonic clock, wraps at 2^32 us (~71.6 min)
  std::uint16_t status = 0;                             // status_bit::*
  std::uint16_t electrode_off = 0;                      // bit i: channel i has lost skin contact
  std::uint16_t saturation = 0;                         // bit i: channel i clipped in the last window
  std::uint16_t artifact = 0;                           // bit i: motion artifact on channel i
  std::uint8_t group_count = 4;                         // 1..kMaxGroups
  std::uint8_t channel_count = 8;                       // 1..kMaxChannels
  std::uint8_t boot_epoch = kBootEpochUnknown;          // differs from the previous boot's; 0 = unknown
  std::array<std::uint16_t, kMaxGroups> levels{};       // 0 relaxed .. 65535 maximal co-contraction
  std::array<std::uint16_t, kMaxChannels> envelopes{};  // Q1.15: 32768 == reference, saturates

  friend constexpr bool operator==(const StreamMessage&, const StreamMessage&) = default;
};

constexpr std::size_t stream_message_size(std::size_t groups, std::size_t channels) {
  return kStreamHeaderSize + 2 * (groups + channels);
}

// Checks counts and masks; the encoder and decoder both apply it.
Error validate(const StreamMessage& msg);

// Writes the message; `written` receives its size. Unused level/envelope slots are not sent.
Error encode_stream(const StreamMessage& msg, std::span<std::uint8_t> out, std::size_t& written);

// Reads a message from the front of `in` (trailing bytes, e.g. HID padding, are ignored).
// Unused slots of `out` are zeroed so that equal wire bytes give equal messages.
Error decode_stream(std::span<const std::uint8_t> in, StreamMessage& out);

}  // namespace tonus::proto
