// What the analogue front end of a board looks like to the core: the ADC
// rails (for clipping and stuck-electrode detection) and the sample rates the
// sampler can run at. Supplied by the HAL; recordings supply their own.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tonus::fw {

struct FrontEnd {
  std::int16_t rail_low = 0;      // lowest code the ADC can return
  std::int16_t rail_high = 4095;  // highest code (12-bit ADC)
  std::int16_t rail_margin = 2;   // codes within this distance of a rail count as clipped
  // Envelope (ADC counts) that maps to envelope 1.0 before any calibration.
  float default_reference = 200.0F;
  // Mains hum RMS (counts) below which the hum is too small to mean a lifted electrode.
  float hum_floor = 40.0F;
  // Low-frequency RMS (counts) below which an excursion is not called a motion artifact.
  float artifact_floor = 40.0F;
  std::uint16_t min_rate_hz = 1000;  // sampler limits; the core refuses other rates
  std::uint16_t max_rate_hz = 2000;
  std::uint16_t rate_step_hz = 1000;  // supported rates: min, min + step, ... max

  [[nodiscard]] constexpr bool supports_rate(std::uint16_t hz) const {
    if (hz < min_rate_hz || hz > max_rate_hz) return false;
    return rate_step_hz == 0 ? hz == min_rate_hz : (hz - min_rate_hz) % rate_step_hz == 0;
  }
  [[nodiscard]] constexpr float span() const { return static_cast<float>(rail_high - rail_low); }
};

}  // namespace tonus::fw
