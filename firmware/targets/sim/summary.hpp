// Run summary of tonus-band-sim: what a host would have seen in the stream.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

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
  // The level stream, kept when asked (a step response is measured on it).
  bool keep_levels = false;
  std::vector<std::uint64_t> level_time_us;
  std::vector<std::array<std::uint16_t, fw::kGroups>> levels;

  Summary();
  void add(const proto::StreamMessage& m, std::uint64_t device_time_us);
};

std::string channel_list(std::uint16_t mask);

// Step response measured on a level stream: for each group that steps (its mean
// level `window_s` after the step differs from the mean `window_s` before by at
// least 5 % of full scale), the normalised level (level - before) / (after -
// before); latency x = first time >= step_us at which the mean of those reaches
// x, minus step_us. -1 where it never does (or no group steps). "after" is the
// mean from window_s after the step to the end.
struct StepLatency {
  double ms10 = -1.0, ms50 = -1.0, ms90 = -1.0;
  std::size_t groups = 0;  // groups that stepped
};
StepLatency step_latency(std::span<const std::uint64_t> t_us,
                         std::span<const std::array<std::uint16_t, fw::kGroups>> levels, std::uint64_t step_us,
                         double window_s = 0.5);

// Device time of frame `frame` from the time of the first report, which the
// device emits at frame ceil(sample_rate / report_rate) - 1 (Bresenham from 0).
std::uint64_t frame_time_us(std::uint64_t first_report_us, std::size_t frame, unsigned sample_rate_hz,
                            unsigned report_rate_hz);

}  // namespace tonus::sim
