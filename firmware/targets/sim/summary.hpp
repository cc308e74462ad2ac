// Run summary of tonus-band-sim: what a host would have seen in the stream.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "tonus/firmware/capacity.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::sim {

struct Summary {
  std::uint64_t reports = 0;
  std::array<std::uint16_t, fw::kGroups> levels_min{};
  std::array<std::uint16_t, fw::kGroups> levels_max{};
  std::array<double, fw::kGroups> levels_sum{};
  std::uint16_t electrode_off = 0, saturation = 0, artifact = 0;  // channels ever flagged
  std::array<double, fw::kChannels> first_off_s{}, first_saturation_s{}, first_artifact_s{};
  std::uint64_t block_lost_reports = 0;
  double first_block_lost_s = -1.0;
  std::uint16_t status_seen = 0;
  std::uint64_t first_time_us = 0;
  bool sequence_continuous = true;
  std::uint16_t last_sequence = 0;

  Summary();
  void add(const proto::StreamMessage& m, std::uint64_t device_time_us);
};

std::string channel_list(std::uint16_t mask);

}  // namespace tonus::sim
