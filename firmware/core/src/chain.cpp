#include "tonus/firmware/chain.hpp"

#include <cmath>
#include <numbers>

namespace tonus::fw {

ChainModel design_chain(const proto::DeviceConfig& cfg) {
  ChainModel m;
  const double fs = cfg.sample_rate_hz;
  const double nyquist = fs / 2.0;
  m.sample_rate_hz = static_cast<float>(fs);
  m.dc_alpha = static_cast<float>(1.0 - std::exp(-2.0 * std::numbers::pi * kDcTrackerHz / fs));

  if (cfg.highpass_dhz != 0) {
    const double fc = cfg.highpass_dhz / 10.0;
    m.highpass_sections = 2;
    for (std::size_t k = 0; k < 2; ++k) m.highpass[k] = design_highpass(fs, fc, butterworth_q(4, k));
  }

  // Harmonics stay clear of Nyquist by a notch width, where the design degenerates.
  if (cfg.notch_hz != 0) {
    for (std::size_t h = 1; h <= cfg.notch_harmonics && m.notch_count < kMaxNotches; ++h) {
      const double f0 = static_cast<double>(cfg.notch_hz) * static_cast<double>(h);
      if (f0 + kNotchBandwidthHz >= nyquist) break;
      m.notch[m.notch_count] = design_notch(fs, f0, kNotchBandwidthHz);
      m.notch_hz[m.notch_count] = static_cast<float>(f0);
      ++m.notch_count;
    }
  }

  if (cfg.lowpass_dhz != 0) {
    const double fc = cfg.lowpass_dhz / 10.0;
    // A corner within 5 % of Nyquist buys nothing but a badly conditioned section.
    if (fc < 0.95 * nyquist) {
      m.lowpass_sections = 2;
      m.lowpass_hz = static_cast<float>(fc);
      for (std::size_t k = 0; k < 2; ++k) m.lowpass[k] = design_lowpass(fs, fc, butterworth_q(4, k));
    } else {
      m.lowpass_dropped = true;
    }
  }

  m.envelope_mode = cfg.envelope_mode;
  const double tau_s = cfg.envelope_tau_ms / 1000.0;
  m.envelope_alpha = static_cast<float>(1.0 - std::exp(-1.0 / (tau_s * fs)));
  const auto window = static_cast<std::uint32_t>(std::lround(tau_s * fs));
  const std::uint32_t safe_window = window < 1 ? 1 : window;
  constexpr auto slots = static_cast<std::uint32_t>(kRmsSlots);
  m.rms_slot_samples = (safe_window + slots - 1) / slots;
  m.rms_slots = (safe_window + m.rms_slot_samples - 1) / m.rms_slot_samples;
  if (m.rms_slots > slots) m.rms_slots = slots;
  m.level = design_level_envelope(cfg);
  return m;
}

void reset(ChannelState& s) { s = ChannelState{}; }

float chain_step(const ChainModel& m, ChannelState& s, float x, ChainTaps& taps) {
  if (!s.primed) {
    s.dc = x;
    s.primed = true;
  }
  const float centred = x - s.dc;
  s.dc += m.dc_alpha * centred;
  taps.centred = centred;

  float y = centred;
  for (std::size_t k = 0; k < m.highpass_sections; ++k) y = biquad_step(m.highpass[k], s.highpass[k], y);
  taps.highpassed = y;
  for (std::size_t k = 0; k < m.notch_count; ++k) y = biquad_step(m.notch[k], s.notch[k], y);
  taps.notched = y;
  for (std::size_t k = 0; k < m.lowpass_sections; ++k) y = biquad_step(m.lowpass[k], s.lowpass[k], y);
  taps.emg = y;

  const float rectified = std::fabs(y);
  level_envelope_step(m.level, s.level, rectified);
  if (m.envelope_mode == proto::EnvelopeMode::linear) {
    s.envelope += m.envelope_alpha * (rectified - s.envelope);
    return s.envelope;
  }

  // Moving RMS: the window is rms_slots slots of rms_slot_samples samples. Each
  // completed slot replaces the oldest; the sum is rebuilt from the ring so
  // float round-off never accumulates.
  s.rms_acc += y * y;
  if (++s.rms_fill < m.rms_slot_samples) return s.envelope;
  s.rms_fill = 0;
  s.rms_ring[s.rms_head] = s.rms_acc;
  s.rms_acc = 0.0F;
  s.rms_head = (s.rms_head + 1) % m.rms_slots;
  float sum = 0.0F;
  for (std::uint32_t k = 0; k < m.rms_slots; ++k) sum += s.rms_ring[k];
  s.envelope = std::sqrt(sum / static_cast<float>(m.rms_slots * m.rms_slot_samples));
  return s.envelope;
}

ChainDelay chain_group_delay(const ChainModel& m, double at_hz) {
  const double fs = static_cast<double>(m.sample_rate_hz);
  double samples = 0.0;
  for (std::size_t k = 0; k < m.highpass_sections; ++k) samples += group_delay_samples(m.highpass[k], at_hz, fs);
  for (std::size_t k = 0; k < m.notch_count; ++k) samples += group_delay_samples(m.notch[k], at_hz, fs);
  for (std::size_t k = 0; k < m.lowpass_sections; ++k) samples += group_delay_samples(m.lowpass[k], at_hz, fs);
  ChainDelay d;
  d.filters_s = samples / fs;
  if (m.envelope_mode == proto::EnvelopeMode::linear) {
    // y += a (x - y): H = a / (1 - (1-a) z^-1), group delay at DC = (1 - a) / a samples.
    const double a = static_cast<double>(m.envelope_alpha);
    d.envelope_s = (1.0 - a) / a / fs;
  } else {
    // Moving average of N samples delays by (N - 1) / 2, plus half a slot of hold on average.
    const double n = static_cast<double>(m.rms_slots) * m.rms_slot_samples;
    d.envelope_s = ((n - 1.0) / 2.0 + m.rms_slot_samples / 2.0) / fs;
  }
  return d;
}

double chain_magnitude(const ChainModel& m, double f_hz) {
  const double fs = static_cast<double>(m.sample_rate_hz);
  double g = 1.0;
  for (std::size_t k = 0; k < m.highpass_sections; ++k) g *= magnitude(m.highpass[k], f_hz, fs);
  for (std::size_t k = 0; k < m.notch_count; ++k) g *= magnitude(m.notch[k], f_hz, fs);
  for (std::size_t k = 0; k < m.lowpass_sections; ++k) g *= magnitude(m.lowpass[k], f_hz, fs);
  return g;
}

}  // namespace tonus::fw
