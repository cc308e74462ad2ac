// Protocol version and the fixed capacities every message is sized against.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tonus::proto {

// Major version carried in every stream, command and response message. A
// decoder rejects other majors; minor additions only use reserved bits,
// reserved bytes and trailing payload bytes, which older decoders ignore.
inline constexpr std::uint8_t kProtocolVersion = 1;
// Minor version of this implementation, reported in DeviceInfo. 1: boot epoch
// in the stream, DeviceInfo's build and boot fields, get_log, enter_bootloader.
inline constexpr std::uint8_t kProtocolMinor = 1;

inline constexpr std::size_t kMaxGroups = 6;     // stiffness groups per stream message
inline constexpr std::size_t kMaxChannels = 16;  // EMG channels per stream message
inline constexpr std::size_t kMaxPairs = 8;      // antagonist channel pairs (kMaxChannels / 2)

// One HID report payload (64-byte report minus the report id) bounds every message.
inline constexpr std::size_t kMaxMessageSize = 63;

}  // namespace tonus::proto
