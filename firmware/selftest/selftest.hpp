// On-target self-test of the signal chain: the Device, unchanged, on a board
// whose sampler plays a built-in synthetic EMG (Scenario::selftest) on a
// virtual clock. Freestanding: the Cortex-M4 self-test image runs it under
// QEMU and prints the result; the host build runs the same function and a
// test compares the two (the same maths on Thumb-2 + FPv4 and on x86-64 SSE).
#pragma once

#include <array>
#include <cstdint>

#include "tonus/firmware/capacity.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::fw {

struct SelftestResult {
  std::uint32_t reports = 0;
  std::uint32_t lost_blocks = 0;
  std::array<std::uint16_t, kGroups> level_max{};
  std::array<std::uint16_t, kGroups> level_at_mid{};  // during the co-contraction step
  std::array<std::uint16_t, kGroups> level_final{};   // during the reciprocal step
  std::array<std::uint16_t, kChannels> envelope_final{};
  std::uint16_t flags_seen = 0;          // electrode_off | saturation | artifact, any channel
  std::int32_t notch_depth_mdb = 0;      // 50 Hz notch at 50 Hz, milli-dB
  std::int32_t highpass_corner_mdb = 0;  // HP cascade at 20 Hz, milli-dB (-3010 expected)
  std::uint32_t group_delay_us = 0;      // whole chain at 80 Hz
  std::uint16_t stream_crc = 0;          // CRC-16 over every encoded stream message
  std::uint64_t poll_ticks = 0;          // ticks of the caller's counter spent inside Device::poll
  std::uint32_t frames = 0;              // frames processed by those polls
};

// A free-running tick counter read around each Device::poll (nullptr: not measured).
using TickCounter = std::uint32_t (*)();

inline constexpr std::uint32_t kSelftestSampleRateHz = 2000;
inline constexpr float kSelftestSeconds = 2.0F;
inline constexpr std::uint64_t kSelftestSeed = 20240905;

// Called with each report (e.g. to stream the first ones over a UART).
using SelftestSink = void (*)(void* context, const proto::StreamMessage& report);

// `ticks` returns a counter that increases (mod 2^32) while the core runs.
void run_selftest(SelftestResult& out, SelftestSink sink = nullptr, void* context = nullptr,
                  TickCounter ticks = nullptr);

// Writes "key=value" lines (NUL-terminated) into `out`; returns the length.
std::size_t format_selftest(const SelftestResult& r, char* out, std::size_t capacity);

}  // namespace tonus::fw
