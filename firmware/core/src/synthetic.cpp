#include "tonus/firmware/synthetic.hpp"

#include <cmath>

namespace tonus::fw {

namespace {

constexpr float kMidScale = 2048.0F;
constexpr float kPi = 3.14159265358979F;

float clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }

bool between(float t, float seconds, float a, float b) { return t >= a * seconds && t < b * seconds; }

bool equal(const char* a, const char* b) {
  while (*a != '\0' && *a == *b) {
    ++a;
    ++b;
  }
  return *a == *b;
}

}  // namespace

const char* to_string(Scenario s) {
  switch (s) {
    case Scenario::rest: return "rest";
    case Scenario::ramp: return "ramp";
    case Scenario::faults: return "faults";
    case Scenario::bursts: return "bursts";
    case Scenario::hum: return "hum";
    case Scenario::dropout: return "dropout";
    case Scenario::selftest: return "selftest";
    case Scenario::step: return "step";
    case Scenario::swell: return "swell";
  }
  return "unknown";
}

bool parse_scenario(const char* name, Scenario& out) {
  for (auto s : {Scenario::rest, Scenario::ramp, Scenario::faults, Scenario::bursts, Scenario::hum, Scenario::dropout,
                 Scenario::selftest, Scenario::step, Scenario::swell}) {
    if (equal(name, to_string(s))) {
      out = s;
      return true;
    }
  }
  return false;
}

std::uint64_t Rng::next() {
  state_ ^= state_ >> 12U;
  state_ ^= state_ << 25U;
  state_ ^= state_ >> 27U;
  return state_ * 0x2545F4914F6CDD1DULL;
}

float Rng::uniform() { return static_cast<float>(next() >> 40U) * (1.0F / 16777216.0F); }

float Rng::gaussian() {
  float s = 0.0F;
  for (int k = 0; k < 12; ++k) s += uniform();
  return s - 6.0F;
}

float sin_turns(float turns) {
  // Reduce to [-0.5, 0.5) turns, then fold into [-pi/2, pi/2] and use the Taylor series to x^11.
  const auto whole = static_cast<float>(static_cast<std::int64_t>(turns + (turns >= 0.0F ? 0.5F : -0.5F)));
  float x = (turns - whole) * 2.0F * kPi;
  if (x > kPi / 2.0F) x = kPi - x;
  if (x < -kPi / 2.0F) x = -kPi - x;
  const float x2 = x * x;
  return x *
         (1.0F - x2 / 6.0F * (1.0F - x2 / 20.0F * (1.0F - x2 / 42.0F * (1.0F - x2 / 72.0F * (1.0F - x2 / 110.0F)))));
}

SyntheticEmg::SyntheticEmg(const SynthSpec& spec) : spec_(spec), rng_(spec.seed) {
  total_ = static_cast<std::size_t>(spec.seconds * spec.sample_rate_hz);
  const double fs = static_cast<double>(spec.sample_rate_hz);
  const double lp = 200.0 < 0.4 * fs ? 200.0 : 0.4 * fs;
  shape_hp_ = design_highpass(fs, 40.0 < 0.2 * fs ? 40.0 : 0.2 * fs, 0.7071);
  shape_lp_ = design_lowpass(fs, lp, 0.7071);
  // Unit RMS: the white noise power gain of the shaping cascade is the energy of its impulse response.
  BiquadState a{}, b{};
  double energy = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const float y = biquad_step(shape_lp_, b, biquad_step(shape_hp_, a, n == 0 ? 1.0F : 0.0F));
    energy += static_cast<double>(y) * static_cast<double>(y);
  }
  shape_gain_ = energy > 0.0 ? static_cast<float>(1.0 / std::sqrt(energy)) : 1.0F;
  for (std::size_t ch = 0; ch < kChannels; ++ch) {
    gain_[ch] = 0.7F + 0.6F * rng_.uniform();
    offset_[ch] = (rng_.uniform() - 0.5F) * 200.0F;
    hum_phase_[ch] = rng_.uniform();
  }
}

FrontEnd SyntheticEmg::front_end() const {
  FrontEnd fe;  // the band's 12-bit ADC, sampled at the generator's one rate
  fe.min_rate_hz = static_cast<std::uint16_t>(std::lround(spec_.sample_rate_hz));
  fe.max_rate_hz = fe.min_rate_hz;
  fe.rate_step_hz = 0;
  return fe;
}

float SyntheticEmg::activation(std::size_t ch, float t) const {
  const float T = spec_.seconds;
  switch (spec_.scenario) {
    case Scenario::rest:
    case Scenario::hum:
    case Scenario::dropout: return 0.0F;
    case Scenario::ramp: return clampf((t / T - 0.1F) / 0.8F, 0.0F, 1.0F);
    case Scenario::faults: return 0.3F;
    case Scenario::bursts: {
      const bool on = static_cast<std::int64_t>(t) % 2 == 1;
      return (on && ch % 2 == 0) ? 0.6F : 0.0F;
    }
    case Scenario::selftest: {
      // rest, then a co-contraction step on pairs 0-1, then a reciprocal one on pairs 2-3
      if (t < 0.3F * T) return 0.0F;
      if (t < 0.65F * T) return ch < 4 ? 0.5F : 0.05F;
      return (ch >= 4 && ch % 2 == 0) ? 0.7F : 0.05F;
    }
    case Scenario::step: {
      // Same expression as the frame times of generate(): the step lands exactly on step_frame.
      const float t_step = static_cast<float>(step_frame(spec_)) / spec_.sample_rate_hz;
      return t >= t_step ? spec_.step_activation : spec_.step_from;
    }
    case Scenario::swell: {
      // 0.5 (1 - cos(2 pi t / P)) = 0.5 (1 - sin(2 pi (t / P + 1/4))): 0 at t = 0, the peak at P / 2.
      if (!(spec_.swell_period_s > 0.0F)) return 0.0F;
      return 0.5F * spec_.swell_peak * (1.0F - sin_turns(t / spec_.swell_period_s + 0.25F));
    }
  }
  return 0.0F;
}

bool SyntheticEmg::lose_block(std::size_t first, std::size_t count) const {
  if (spec_.scenario != Scenario::faults) return false;
  const auto at = static_cast<std::size_t>(FaultScript::kLostBlockAt * static_cast<float>(total_));
  return at >= first && at < first + count;
}

float SyntheticEmg::sample(std::size_t ch, float t) {
  const float T = spec_.seconds;
  const float white = rng_.gaussian();
  const float shaped =
      shape_gain_ * biquad_step(shape_lp_, lp_state_[ch], biquad_step(shape_hp_, hp_state_[ch], white));
  float emg = activation(ch, t) * spec_.mvc_rms_counts * gain_[ch] * shaped;
  const float noise = spec_.noise_rms_counts * rng_.gaussian();
  float hum_amp = spec_.hum_counts;
  float extra = 0.0F;
  if (spec_.scenario == Scenario::hum) hum_amp = 25.0F;
  if (spec_.scenario == Scenario::faults) {
    if (ch == FaultScript::kOffChannel && between(t, T, FaultScript::kOffStart, FaultScript::kOffEnd)) {
      emg = 0.0F;
      hum_amp = 400.0F;  // a floating input picks up the mains
    }
    if (ch == FaultScript::kSaturatedChannel && between(t, T, FaultScript::kSatStart, FaultScript::kSatEnd)) {
      emg *= 12.0F;
    }
    if (ch == FaultScript::kArtifactChannel && between(t, T, FaultScript::kArtifactStart, FaultScript::kArtifactEnd)) {
      const float u =
          (t - FaultScript::kArtifactStart * T) / ((FaultScript::kArtifactEnd - FaultScript::kArtifactStart) * T);
      extra = 900.0F * sin_turns(0.5F * u);  // one slow half-wave swing of the baseline
    }
  }
  if (spec_.scenario == Scenario::dropout && ch == 3 && t >= 0.25F * T) return 4095.0F;
  const float hum = hum_amp * sin_turns(hum_phase_[ch] + spec_.mains_hz * t);
  return kMidScale + offset_[ch] + emg + noise + hum + extra;
}

std::size_t SyntheticEmg::generate(std::span<std::int16_t> out, std::size_t frames) {
  std::size_t n = 0;
  for (; n < frames && frame_ < total_ && (n + 1) * kChannels <= out.size(); ++n, ++frame_) {
    const float t = static_cast<float>(frame_) / spec_.sample_rate_hz;
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      const float v = clampf(sample(ch, t), 0.0F, 4095.0F);
      out[n * kChannels + ch] = static_cast<std::int16_t>(std::lround(v));
    }
  }
  return n;
}

}  // namespace tonus::fw
