#include "summary.hpp"

#include <cmath>

namespace tonus::sim {

Summary::Summary() {
  levels_min.fill(0xFFFF);
  first_off_s.fill(-1.0);
  first_saturation_s.fill(-1.0);
  first_artifact_s.fill(-1.0);
}

void Summary::add(const proto::StreamMessage& m, std::uint64_t t_us) {
  if (reports == 0) {
    first_time_us = t_us;
  } else if (static_cast<std::uint16_t>(last_sequence + 1) != m.sequence) {
    sequence_continuous = false;
  }
  last_sequence = m.sequence;
  ++reports;
  const double t = static_cast<double>(t_us) * 1e-6;
  for (std::size_t g = 0; g < fw::kGroups; ++g) {
    levels_min[g] = m.levels[g] < levels_min[g] ? m.levels[g] : levels_min[g];
    levels_max[g] = m.levels[g] > levels_max[g] ? m.levels[g] : levels_max[g];
    levels_sum[g] += m.levels[g];
  }
  for (std::size_t ch = 0; ch < fw::kChannels; ++ch) {
    const auto bit = static_cast<std::uint16_t>(1U << ch);
    if ((m.electrode_off & bit) != 0 && first_off_s[ch] < 0) first_off_s[ch] = t;
    if ((m.saturation & bit) != 0 && first_saturation_s[ch] < 0) first_saturation_s[ch] = t;
    if ((m.artifact & bit) != 0 && first_artifact_s[ch] < 0) first_artifact_s[ch] = t;
  }
  electrode_off |= m.electrode_off;
  saturation |= m.saturation;
  artifact |= m.artifact;
  status_seen |= m.status;
  if (keep_levels) {
    level_time_us.push_back(t_us);
    levels.push_back({m.levels[0], m.levels[1], m.levels[2], m.levels[3]});
  }
  if ((m.status & proto::status_bit::block_lost) != 0) {
    ++block_lost_reports;
    if (first_block_lost_s < 0) first_block_lost_s = t;
  }
}

std::string channel_list(std::uint16_t mask) {
  std::string s;
  for (std::size_t ch = 0; ch < 16; ++ch) {
    if (((static_cast<unsigned>(mask) >> ch) & 1U) == 0) continue;
    if (!s.empty()) s.push_back(',');
    s.append(std::to_string(ch));
  }
  return s.empty() ? "-" : s;
}

StepLatency step_latency(std::span<const std::uint64_t> t_us,
                         std::span<const std::array<std::uint16_t, fw::kGroups>> levels, std::uint64_t step_us,
                         double window_s) {
  StepLatency r;
  const auto window_us = static_cast<std::uint64_t>(window_s * 1e6);
  std::array<double, fw::kGroups> before{}, after{};
  std::size_t n_before = 0, n_after = 0;
  for (std::size_t k = 0; k < t_us.size() && k < levels.size(); ++k) {
    const bool is_before = t_us[k] < step_us && t_us[k] + window_us >= step_us;
    const bool is_after = t_us[k] >= step_us + window_us;
    for (std::size_t g = 0; g < fw::kGroups; ++g) {
      if (is_before) before[g] += levels[k][g];
      if (is_after) after[g] += levels[k][g];
    }
    n_before += is_before ? 1 : 0;
    n_after += is_after ? 1 : 0;
  }
  if (n_before == 0 || n_after == 0) return r;
  std::array<bool, fw::kGroups> steps{};
  for (std::size_t g = 0; g < fw::kGroups; ++g) {
    before[g] /= static_cast<double>(n_before);
    after[g] /= static_cast<double>(n_after);
    steps[g] = std::fabs(after[g] - before[g]) >= 0.05 * 65535.0;
    if (steps[g]) ++r.groups;
  }
  if (r.groups == 0) return r;
  std::array<double*, 3> out{&r.ms10, &r.ms50, &r.ms90};
  const std::array<double, 3> fraction{0.1, 0.5, 0.9};
  for (std::size_t k = 0; k < t_us.size() && k < levels.size(); ++k) {
    if (t_us[k] < step_us) continue;
    double u = 0.0;
    for (std::size_t g = 0; g < fw::kGroups; ++g) {
      if (steps[g]) u += (levels[k][g] - before[g]) / (after[g] - before[g]);
    }
    u /= static_cast<double>(r.groups);
    for (std::size_t i = 0; i < 3; ++i) {
      if (*out[i] < 0.0 && u >= fraction[i]) *out[i] = static_cast<double>(t_us[k] - step_us) * 1e-3;
    }
  }
  return r;
}

std::uint64_t frame_time_us(std::uint64_t first_report_us, std::size_t frame, unsigned sample_rate_hz,
                            unsigned report_rate_hz) {
  const std::size_t first_frame = (sample_rate_hz + report_rate_hz - 1) / report_rate_hz - 1;
  const auto frames = static_cast<double>(frame) - static_cast<double>(first_frame);
  const std::int64_t delta_us = std::llround(frames * 1e6 / static_cast<double>(sample_rate_hz));
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(first_report_us) + delta_us);
}

}  // namespace tonus::sim
