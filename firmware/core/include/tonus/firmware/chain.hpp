// Per-channel surface-EMG conditioning chain (causal, float on the FPU):
//
//   raw counts -> DC removal (one-pole tracker, 0.5 Hz)
//              -> high-pass 20 Hz, 4th-order Butterworth (2 biquads)   [SENIAM, De Luca 2010]
//              -> mains notches f, 2f, 3f ... below Nyquist (1 biquad each, 4 Hz wide)
//              -> low-pass 450 Hz, 4th-order Butterworth (2 biquads), only below Nyquist
//              -> full-wave rectification
//              -> linear envelope: one-pole low-pass with time constant tau (default 100 ms)
//                 or moving RMS over a window of tau (displayed, calibrated on)
//              -> level envelope: the same smoothness in steady effort, a memory
//                 restarted at each change of effort (level_envelope.hpp)
//
// The model (ChainModel) is designed once from the configuration; the data
// (ChannelState) is preallocated and mutated by chain_step, a pure function of both.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "tonus/firmware/biquad.hpp"
#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/level_envelope.hpp"
#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr double kDcTrackerHz = 0.5;       // DC removal corner, far below the 20 Hz high-pass
inline constexpr double kNotchBandwidthHz = 4.0;  // tolerates +-0.2 Hz mains drift with >= 20 dB rejection
inline constexpr double kButterworthOrder = 4.0;  // high-pass and low-pass orders (2 sections each)
inline constexpr double kReferenceEmgHz = 80.0;   // typical surface-EMG median frequency (De Luca 1997)

struct ChainModel {
  float sample_rate_hz = 2000.0F;
  float dc_alpha = 0.0F;  // one-pole DC tracker gain per sample
  std::size_t highpass_sections = 0;
  std::array<Biquad, 2> highpass{};
  std::size_t notch_count = 0;
  std::array<Biquad, kMaxNotches> notch{};
  std::array<float, kMaxNotches> notch_hz{};
  std::size_t lowpass_sections = 0;
  std::array<Biquad, 2> lowpass{};
  float lowpass_hz = 0.0F;       // realised corner, 0 when dropped (at or above Nyquist)
  bool lowpass_dropped = false;  // configured but not realisable at this rate
  proto::EnvelopeMode envelope_mode = proto::EnvelopeMode::linear;
  float envelope_alpha = 0.0F;         // one-pole envelope gain: 1 - exp(-1 / (tau fs))
  std::uint32_t rms_slot_samples = 1;  // samples summed per RMS slot
  std::uint32_t rms_slots = 1;         // slots in the RMS window
  LevelEnvelopeModel level{};          // the levels' envelope (level_envelope.hpp)
};

// Designs the chain for a configuration that passed proto::check_config.
ChainModel design_chain(const proto::DeviceConfig& cfg);

struct ChannelState {
  bool primed = false;  // first sample seeds the DC tracker (no start-up step)
  float dc = 0.0F;
  std::array<BiquadState, 2> highpass{};
  std::array<BiquadState, kMaxNotches> notch{};
  std::array<BiquadState, 2> lowpass{};
  float envelope = 0.0F;  // counts (rectified EMG, smoothed)
  // moving RMS: ring of per-slot sums of squares
  std::array<float, kRmsSlots> rms_ring{};
  float rms_acc = 0.0F;
  std::uint32_t rms_fill = 0;
  std::uint32_t rms_head = 0;
  LevelEnvelopeState level{};
};

// Intermediate signals the quality detectors look at, produced for free by the chain.
struct ChainTaps {
  float centred = 0.0F;     // after DC removal
  float highpassed = 0.0F;  // after the high-pass, before the notches
  float notched = 0.0F;     // after the notches
  float emg = 0.0F;         // conditioned EMG (after the low-pass)
};

// One sample through the chain; returns the envelope in ADC counts.
float chain_step(const ChainModel& m, ChannelState& s, float x, ChainTaps& taps);

void reset(ChannelState& s);

// The envelope the stiffness levels use (fast after a change of effort, see
// level_envelope.hpp), in the units of the one chain_step returns.
inline float level_envelope(const ChainModel& m, const ChannelState& s) {
  return level_envelope_value(m.level, s.level);
}

// Latency of the chain as the performer feels it, in seconds.
struct ChainDelay {
  double filters_s = 0.0;   // band-pass + notches, group delay at kReferenceEmgHz
  double envelope_s = 0.0;  // envelope smoother, group delay at DC
  [[nodiscard]] double total_s() const { return filters_s + envelope_s; }
};
ChainDelay chain_group_delay(const ChainModel& m, double at_hz = kReferenceEmgHz);

// Magnitude of the filter cascade (high-pass, notches, low-pass) at f.
double chain_magnitude(const ChainModel& m, double f_hz);

}  // namespace tonus::fw
