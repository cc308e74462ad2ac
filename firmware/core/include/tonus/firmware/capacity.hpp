// Fixed capacities of the band, checked at compile time against the protocol.
#pragma once

#include <cstddef>
#include <cstdint>

#include "tonus/protocol/limits.hpp"

namespace tonus::fw {

inline constexpr std::uint8_t kFirmwareMajor = 0;
inline constexpr std::uint8_t kFirmwareMinor = 6;
inline constexpr std::uint8_t kFirmwarePatch = 0;

inline constexpr std::size_t kChannels = 8;  // 4 antagonist pairs: channel 2p flexor, 2p+1 extensor
inline constexpr std::size_t kPairs = kChannels / 2;
inline constexpr std::size_t kGroups = 4;           // stiffness groups the band reports
inline constexpr std::size_t kMaxBlockFrames = 64;  // frames (one sample per channel) in one DMA half-buffer
inline constexpr std::size_t kMaxNotches = 8;       // mains fundamental + harmonics
inline constexpr std::size_t kRmsSlots = 64;        // moving-RMS window resolution (sub-block sums)

static_assert(kChannels <= proto::kMaxChannels);
static_assert(kPairs <= proto::kMaxPairs);
static_assert(kGroups <= proto::kMaxGroups);

}  // namespace tonus::fw
