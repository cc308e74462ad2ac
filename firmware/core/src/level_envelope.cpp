#include "tonus/firmware/level_envelope.hpp"

#include <cmath>

namespace tonus::fw {

namespace {

std::uint32_t samples(double ms, double fs) {
  const auto n = static_cast<std::uint32_t>(std::lround(ms * fs / 1000.0));
  return n < 1 ? 1 : n;
}

}  // namespace

LevelEnvelopeModel design_level_envelope(const proto::DeviceConfig& cfg) {
  LevelEnvelopeModel m;
  const double fs = cfg.sample_rate_hz;
  const double tau_ms = cfg.envelope_tau_ms;
  double fast_ms = kLevelFastTauMs;
  if (fast_ms < kLevelFastMinSamples * 1000.0 / fs) fast_ms = kLevelFastMinSamples * 1000.0 / fs;
  if (fast_ms > tau_ms) fast_ms = tau_ms;  // never slower than the configured envelope
  m.fast_alpha = static_cast<float>(1.0 - std::exp(-1000.0 / (fast_ms * fs)));
  m.slow_alpha = static_cast<float>(1.0 - std::exp(-1000.0 / (tau_ms * fs)));
  // The running mean's weight 1/n falls to the one-pole's gain at n = 1 / slow_alpha.
  m.memory_max = static_cast<std::uint32_t>(std::floor(1.0 / static_cast<double>(m.slow_alpha)));
  if (m.memory_max < 1) m.memory_max = 1;
  m.confirm = samples(kLevelConfirmMs, fs);
  if (m.confirm > m.memory_max) m.confirm = m.memory_max;
  m.hold = samples(kLevelHoldMs, fs);
  m.scale = cfg.envelope_mode == proto::EnvelopeMode::moving_rms ? kRmsOverMeanAbs : 1.0F;
  return m;
}

}  // namespace tonus::fw
