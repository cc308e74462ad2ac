// Seeded, reproducible synthetic surface EMG for the 8 channels of the band,
// with a known activation per channel (the envelope the chain must recover).
//
// Model per channel: EMG = band-limited Gaussian noise (40..200 Hz shaping,
// the bulk of the surface-EMG spectrum) scaled by activation(t) * mvc_rms,
// plus an electrode/amplifier noise floor, mains hum, a DC offset near
// mid-scale, quantised to a 12-bit ADC (clipped at its rails). Scenarios add
// scripted faults. Freestanding (no heap; no transcendental libm calls in the
// sample loop, only exact ones such as lround), so the Cortex-M4 self-test
// generates bit-identical input to the host build.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/firmware/biquad.hpp"
#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/front_end.hpp"

namespace tonus::fw {

enum class Scenario : std::uint8_t {
  rest,      // relaxed: noise floor and a little hum
  ramp,      // co-contraction rising linearly from rest (t < 10 %) to maximal (t > 90 %) on every pair
  faults,    // steady co-contraction 0.3 with scripted faults (see FaultScript)
  bursts,    // 1 s contraction bursts every 2 s, flexors only (reciprocal activation)
  hum,       // rest with strong mains hum on every channel (electrodes on, poor reference)
  dropout,   // channel 3 stuck at the high rail (broken lead) from 25 % on
  selftest,  // short mixed pattern for the on-target self-test
  step,      // co-contraction step on every channel at half the duration: step_from, then step_activation
  swell,     // co-contraction rising from rest to swell_peak and falling back, every swell_period_s (1 - cos)
};

const char* to_string(Scenario s);
bool parse_scenario(const char* name, Scenario& out);

// Times of the scripted faults of Scenario::faults, as fractions of the duration.
struct FaultScript {
  static constexpr std::size_t kOffChannel = 2;  // electrode lifted: mains hum, no EMG
  static constexpr float kOffStart = 0.20F, kOffEnd = 0.35F;
  static constexpr std::size_t kSaturatedChannel = 5;  // gain far too high: clips at both rails
  static constexpr float kSatStart = 0.45F, kSatEnd = 0.55F;
  static constexpr float kLostBlockAt = 0.65F;        // the sampler loses one block
  static constexpr std::size_t kArtifactChannel = 0;  // cable motion: a 400 ms low-frequency swing
  static constexpr float kArtifactStart = 0.75F, kArtifactEnd = 0.80F;
};

struct SynthSpec {
  Scenario scenario = Scenario::rest;
  std::uint64_t seed = 1;
  float sample_rate_hz = 2000.0F;
  float seconds = 10.0F;
  float mains_hz = 50.0F;
  float hum_counts = 3.0F;        // hum amplitude with electrodes on
  float noise_rms_counts = 4.0F;  // amplifier + electrode noise
  float mvc_rms_counts = 300.0F;  // EMG RMS at activation 1 (before the per-channel gain)
  float step_from = 0.0F;         // Scenario::step: the effort before the step (0: rest)
  float step_activation = 0.5F;   // Scenario::step: the effort after the step
  float swell_period_s = 10.0F;   // Scenario::swell: one rise and fall
  float swell_peak = 0.8F;        // Scenario::swell: the effort at the top
};

// Scenario::step: the first frame of the new effort (half the duration, rounded down).
inline std::size_t step_frame(const SynthSpec& spec) {
  return static_cast<std::size_t>(spec.seconds * spec.sample_rate_hz) / 2;
}

// Deterministic xorshift64* generator.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed == 0 ? 0x9E3779B97F4A7C15ULL : seed) {}
  std::uint64_t next();
  float uniform();   // [0, 1)
  float gaussian();  // ~N(0, 1), Irwin-Hall sum of 12 uniforms
 private:
  std::uint64_t state_;
};

// sin(2 pi turns), polynomial, no libm: identical on every IEEE float unit.
float sin_turns(float turns);

class SyntheticEmg {
 public:
  explicit SyntheticEmg(const SynthSpec& spec);

  [[nodiscard]] FrontEnd front_end() const;
  [[nodiscard]] const SynthSpec& spec() const { return spec_; }
  [[nodiscard]] std::size_t total_frames() const { return total_; }
  [[nodiscard]] std::size_t position() const { return frame_; }

  // Known activation of a channel at time t (0 rest .. 1 MVC), the envelope to recover.
  [[nodiscard]] float activation(std::size_t ch, float t_s) const;
  // Per-channel gain between activation and EMG RMS (electrode placement, skin).
  [[nodiscard]] float channel_gain(std::size_t ch) const { return gain_[ch]; }
  // Whether the sampler should drop the block covering frames [first, first + count).
  [[nodiscard]] bool lose_block(std::size_t first, std::size_t count) const;

  // Writes up to `frames` frames (frame-major, kChannels per frame); returns frames written (0 at the end).
  std::size_t generate(std::span<std::int16_t> out, std::size_t frames);

 private:
  float sample(std::size_t ch, float t_s);

  SynthSpec spec_;
  std::size_t total_ = 0;
  std::size_t frame_ = 0;
  Rng rng_;
  Biquad shape_hp_{}, shape_lp_{};
  float shape_gain_ = 1.0F;  // makes the shaped noise unit RMS
  std::array<BiquadState, kChannels> hp_state_{}, lp_state_{};
  std::array<float, kChannels> gain_{};
  std::array<float, kChannels> offset_{};
  std::array<float, kChannels> hum_phase_{};
};

}  // namespace tonus::fw
