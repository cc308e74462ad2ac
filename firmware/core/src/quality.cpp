#include "tonus/firmware/quality.hpp"

#include <cmath>

namespace tonus::fw {

QualityModel design_quality(const FrontEnd& fe, float sample_rate_hz, bool notch_enabled) {
  QualityModel m;
  m.front_end = fe;
  const auto window = static_cast<std::uint32_t>(std::lround(kQualityWindowS * sample_rate_hz));
  m.window_samples = window < 10 ? 10 : window;
  const auto sat = static_cast<std::uint32_t>(std::ceil(kSaturationFraction * static_cast<float>(m.window_samples)));
  m.saturation_count = sat < 2 ? 2 : sat;
  m.stuck_count = static_cast<std::uint32_t>(kStuckFraction * static_cast<float>(m.window_samples));
  m.power_alpha = 1.0F / static_cast<float>(m.window_samples);
  m.baseline_alpha = 1.0F / (kArtifactBaselineS * sample_rate_hz);
  m.hum_check = notch_enabled;
  return m;
}

bool quality_step(const QualityModel& m, QualityState& s, std::int16_t raw, const ChainTaps& taps) {
  const FrontEnd& fe = m.front_end;
  const bool low = raw <= fe.rail_low + fe.rail_margin;
  const bool high = raw >= fe.rail_high - fe.rail_margin;
  if (low || high) ++s.clipped;
  if (s.count == 0) s.lo = s.hi = raw;
  if (raw < s.lo) s.lo = raw;
  if (raw > s.hi) s.hi = raw;
  if (low || high) ++s.at_rail;

  const float hum = taps.highpassed - taps.notched;
  const float lf = taps.centred - taps.highpassed;
  s.hum_power += m.power_alpha * (hum * hum - s.hum_power);
  s.emg_power += m.power_alpha * (taps.emg * taps.emg - s.emg_power);
  s.lf_power += m.power_alpha * (lf * lf - s.lf_power);

  if (++s.count < m.window_samples) return false;

  QualityFlags f;
  s.flat_windows = s.lo == s.hi ? s.flat_windows + 1 : 0;
  const bool stuck = s.at_rail >= m.stuck_count || s.flat_windows >= kFlatWindows;
  const bool hum_dominates =
      m.hum_check && s.hum_power > fe.hum_floor * fe.hum_floor && s.hum_power > kHumDominanceRatio * s.emg_power;
  f.electrode_off = stuck || hum_dominates;
  f.saturation = s.clipped >= m.saturation_count && !stuck;

  if (!s.baseline_primed) {
    s.lf_baseline = s.lf_power;
    s.baseline_primed = true;
  }
  const float floor = fe.artifact_floor * fe.artifact_floor;
  f.artifact = !f.electrode_off && s.lf_power > floor && s.lf_power > kArtifactEmgRatio * s.emg_power &&
               s.lf_power > kArtifactBaselineRatio * s.lf_baseline;
  // The baseline learns only from windows without an artifact, one window at a time.
  if (!f.artifact) {
    const float k = m.baseline_alpha * static_cast<float>(m.window_samples);
    s.lf_baseline += (k < 1.0F ? k : 1.0F) * (s.lf_power - s.lf_baseline);
  }

  s.held.electrode_off = f.electrode_off || s.current.electrode_off;
  s.held.saturation = f.saturation || s.current.saturation;
  s.held.artifact = f.artifact || s.current.artifact;
  s.current = f;
  s.count = 0;
  s.clipped = 0;
  s.at_rail = 0;
  return true;
}

}  // namespace tonus::fw
