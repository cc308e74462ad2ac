// Signal-quality flags per channel, computed from the chain's taps over
// windows of 100 ms:
//   electrode off - mains hum dominates the EMG (a lifted electrode is a high
//                   impedance antenna), or the input is stuck at a rail or flat;
//   saturation    - samples within rail_margin of a rail, counted per window;
//   artifact      - low-frequency (below the high-pass) energy far above both
//                   the EMG in band and its own slow baseline (cable or skin motion).
// A flag is raised at the end of the window that shows it and held for at
// least one more window so a host at a 1 kHz report rate cannot miss it.
#pragma once

#include <cstdint>

#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/front_end.hpp"

namespace tonus::fw {

inline constexpr float kQualityWindowS = 0.1F;
inline constexpr float kHumDominanceRatio = 4.0F;      // hum power / EMG power (6 dB)
inline constexpr float kStuckFraction = 0.9F;          // of a window at a rail
inline constexpr float kSaturationFraction = 0.01F;    // of a window clipped (at least 2 samples)
inline constexpr float kArtifactEmgRatio = 10.0F;      // low-frequency power / in-band EMG power (10 dB)
inline constexpr float kArtifactBaselineRatio = 8.0F;  // low-frequency power / its slow baseline
inline constexpr float kArtifactBaselineS = 2.0F;
inline constexpr std::uint32_t kFlatWindows = 3;  // consecutive windows of one constant code

struct QualityModel {
  FrontEnd front_end{};
  std::uint32_t window_samples = 200;
  std::uint32_t saturation_count = 2;
  std::uint32_t stuck_count = 180;
  float power_alpha = 0.0F;     // one-pole smoothing of powers over a window
  float baseline_alpha = 0.0F;  // slow baseline of low-frequency power
  bool hum_check = false;       // only with a notch configured
};

QualityModel design_quality(const FrontEnd& fe, float sample_rate_hz, bool notch_enabled);

struct QualityFlags {
  bool electrode_off = false;
  bool saturation = false;
  bool artifact = false;
};

struct QualityState {
  std::uint32_t count = 0;
  std::uint32_t clipped = 0;
  std::uint32_t at_rail = 0;
  std::int16_t lo = 0, hi = 0;
  std::uint32_t flat_windows = 0;
  float hum_power = 0.0F;
  float emg_power = 0.0F;
  float lf_power = 0.0F;
  float lf_baseline = 0.0F;
  bool baseline_primed = false;
  QualityFlags current{};  // from the last completed window
  QualityFlags held{};     // what reports show: current OR the window before
};

// One raw sample and its chain taps. Returns true when a window completed.
bool quality_step(const QualityModel& m, QualityState& s, std::int16_t raw, const ChainTaps& taps);

}  // namespace tonus::fw
