#include "summary.hpp"

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

}  // namespace tonus::sim
