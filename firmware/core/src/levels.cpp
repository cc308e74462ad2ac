#include "tonus/firmware/levels.hpp"

#include <cmath>

namespace tonus::fw {

LevelModel design_levels(const proto::DeviceConfig& cfg) {
  LevelModel m;
  m.measure = cfg.measure;
  m.dead_band = static_cast<float>(cfg.dead_band) / static_cast<float>(proto::kLevelMax);
  m.hysteresis = cfg.hysteresis;
  m.curve = cfg.curve;
  m.exponent = static_cast<float>(cfg.curve_exponent_milli) / 1000.0F;
  for (std::size_t p = 0; p < kPairs; ++p) m.pair_group[p] = cfg.pair_group[p];
  return m;
}

float cocontraction(proto::CoContractionMeasure measure, float flexor, float extensor) {
  const float lo = flexor < extensor ? flexor : extensor;
  const float hi = flexor < extensor ? extensor : flexor;
  if (measure == proto::CoContractionMeasure::min_normalised) return lo;
  if (hi <= 1e-6F) return 0.0F;
  return (lo / hi) * (lo + hi) * 0.5F;
}

std::uint16_t level_target(const LevelModel& m, float c) {
  if (!(c > m.dead_band)) return 0;  // also catches NaN
  float u = (c - m.dead_band) / (1.0F - m.dead_band);
  if (u > 1.0F) u = 1.0F;
  if (m.curve == proto::LevelCurve::power) u = std::pow(u, m.exponent);
  return static_cast<std::uint16_t>(std::lround(u * static_cast<float>(proto::kLevelMax)));
}

void levels_step(const LevelModel& m, LevelState& s, std::span<const float, kPairs> c,
                 std::span<std::uint16_t, kGroups> groups) {
  for (std::size_t p = 0; p < kPairs; ++p) {
    const std::uint16_t target = level_target(m, c[p]);
    const std::uint16_t now = s.pair_level[p];
    const int diff = static_cast<int>(target) - static_cast<int>(now);
    const bool at_end = target == 0 || target == proto::kLevelMax;
    if (at_end || diff >= m.hysteresis || -diff >= m.hysteresis) s.pair_level[p] = target;
  }
  for (std::size_t g = 0; g < kGroups; ++g) groups[g] = 0;
  for (std::size_t p = 0; p < kPairs; ++p) {
    const std::uint8_t g = m.pair_group[p];
    if (g < kGroups && s.pair_level[p] > groups[g]) groups[g] = s.pair_level[p];
  }
}

}  // namespace tonus::fw
