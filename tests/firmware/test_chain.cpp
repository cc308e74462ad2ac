// The per-channel chain: corners adapt to the sample rate, mains hum is
// rejected, a synthetic EMG's known envelope is recovered, and the reported
// group delay is the delay a step actually shows.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "tonus/firmware/chain.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/firmware/synthetic.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

constexpr double kPi = std::numbers::pi;

proto::DeviceConfig config_at(std::uint16_t rate) {
  FrontEnd fe;
  fe.min_rate_hz = rate;
  fe.max_rate_hz = rate;
  fe.rate_step_hz = 0;
  return default_config(fe);
}

// RMS of the conditioned EMG for a sine of amplitude `amp` at f, after 1 s of settling.
double emg_rms(const ChainModel& m, double f, double amp) {
  ChannelState s;
  ChainTaps taps;
  const double fs = m.sample_rate_hz;
  double acc = 0.0;
  int n = 0;
  for (int k = 0; k < static_cast<int>(3 * fs); ++k) {
    const double x = 2048.0 + amp * std::sin(2.0 * kPi * f * k / fs);
    chain_step(m, s, static_cast<float>(x), taps);
    if (k >= static_cast<int>(fs)) {
      acc += static_cast<double>(taps.emg) * static_cast<double>(taps.emg);
      ++n;
    }
  }
  return std::sqrt(acc / n);
}

}  // namespace

TEST_CASE("corners adapt to the sample rate") {
  SUBCASE("2 kHz: HP 20, LP 450, notches 50..200") {
    const ChainModel m = design_chain(config_at(2000));
    CHECK(m.highpass_sections == 2);
    CHECK(m.lowpass_sections == 2);
    CHECK(m.lowpass_hz == doctest::Approx(450.0F));
    REQUIRE(m.notch_count == 4);
    CHECK(m.notch_hz[3] == doctest::Approx(200.0F));
  }
  SUBCASE("1 kHz with 8 harmonics: notches stop below Nyquist") {
    proto::DeviceConfig cfg = config_at(1000);
    cfg.notch_harmonics = 8;
    const ChainModel m = design_chain(cfg);
    CHECK(m.notch_count == 8);  // 50..400 Hz, all below 500
    cfg.notch_hz = 60;
    CHECK(design_chain(cfg).notch_count == 8);  // 60..480 < 496
    cfg.sample_rate_hz = 800;
    cfg.lowpass_dhz = 3500;
    CHECK(design_chain(cfg).notch_count == 6);  // 60..360 below 400 - width
  }
  SUBCASE("200 Hz (Myo): the default drops the 450 Hz low-pass, one 50 Hz notch") {
    const proto::DeviceConfig cfg = config_at(200);
    CHECK(cfg.lowpass_dhz == 0);
    CHECK(proto::check_config(cfg, 4) == proto::ConfigField::none);
    const ChainModel m = design_chain(cfg);
    CHECK(m.lowpass_sections == 0);
    CHECK(m.notch_count == 1);
  }
  SUBCASE("a corner too close to Nyquist is dropped, not realised badly") {
    proto::DeviceConfig cfg = config_at(1000);
    cfg.lowpass_dhz = 4900;  // 490 Hz passes check_config (< 500) but is 98 % of Nyquist
    const ChainModel m = design_chain(cfg);
    CHECK(m.lowpass_sections == 0);
    CHECK(m.lowpass_dropped);
  }
}

TEST_CASE("mains hum is rejected by at least 40 dB, EMG band kept") {
  for (int rate_i : {1000, 2000}) {
    const auto rate = static_cast<std::uint16_t>(rate_i);
    const ChainModel m = design_chain(config_at(rate));
    for (double f : {50.0, 100.0, 150.0, 200.0}) {
      const double in = 1000.0 / std::sqrt(2.0);
      const double db = 20.0 * std::log10(emg_rms(m, f, 1000.0) / in);
      INFO("rate " << rate << " f " << f << " attenuation " << db << " dB");
      CHECK(db < -40.0);
    }
    // 50.2 Hz (mains drift) still at least 18 dB down.
    CHECK(20.0 * std::log10(emg_rms(m, 50.2, 1000.0) / (1000.0 / std::sqrt(2.0))) < -18.0);
    // Pass band: the run matches the design magnitude and is within 0.5 dB of unity.
    for (double f : {80.0, 130.0, 230.0}) {
      const double gain = emg_rms(m, f, 1000.0) / (1000.0 / std::sqrt(2.0));
      CHECK(gain == doctest::Approx(chain_magnitude(m, f)).epsilon(0.01));
      CHECK(std::fabs(20.0 * std::log10(gain)) < 0.5);
    }
  }
  SUBCASE("60 Hz mains") {
    proto::DeviceConfig cfg = config_at(2000);
    cfg.notch_hz = 60;
    const ChainModel m = design_chain(cfg);
    CHECK(20.0 * std::log10(emg_rms(m, 60.0, 1000.0) / (1000.0 / std::sqrt(2.0))) < -40.0);
    CHECK(20.0 * std::log10(emg_rms(m, 180.0, 1000.0) / (1000.0 / std::sqrt(2.0))) < -40.0);
  }
}

TEST_CASE("the envelope of a synthetic EMG recovers its known activation") {
  // Expected envelope: mean |x| of Gaussian noise = sqrt(2/pi) RMS, where the RMS
  // is that of the generator's EMG and noise after the chain's own filters,
  // computed in the frequency domain from the design (not from the run).
  SynthSpec spec;
  spec.scenario = Scenario::ramp;
  spec.seconds = 10.0F;
  spec.seed = 7;
  const double fs = static_cast<double>(spec.sample_rate_hz);
  SyntheticEmg gen(spec);
  const ChainModel m = design_chain(config_at(2000));
  const Biquad shp = design_highpass(fs, 40.0, 0.7071), slp = design_lowpass(fs, 200.0, 0.7071);
  double emg_num = 0.0, emg_den = 0.0, noise_num = 0.0, noise_den = 0.0;
  for (int k = 1; 0.25 * k < fs / 2.0; ++k) {
    const double f = 0.25 * k;
    const double shape = magnitude(shp, f, fs) * magnitude(slp, f, fs);
    const double h = chain_magnitude(m, f);
    emg_num += shape * shape * h * h;
    emg_den += shape * shape;
    noise_num += h * h;
    noise_den += 1.0;
  }
  const double emg_gain = std::sqrt(emg_num / emg_den);
  const double noise_rms = static_cast<double>(spec.noise_rms_counts) * std::sqrt(noise_num / noise_den);

  std::array<ChannelState, kChannels> st{};
  std::vector<std::int16_t> frame(kChannels);
  const auto total = gen.total_frames();
  const double delay = chain_group_delay(m).total_s();
  // Compare 1 s means of envelope and expectation (shifted by the reported delay):
  // each within 15 % (the estimation noise of a 100 ms envelope of random EMG),
  // and the whole ramp within 3 % (no bias).
  std::array<double, kChannels> got{}, want{};
  double got_all = 0.0, want_all = 0.0;
  int checked = 0;
  for (std::size_t k = 0; k < total; ++k) {
    gen.generate(frame, 1);
    const double t = static_cast<double>(k) / fs;
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      ChainTaps taps;
      const float env = chain_step(m, st[ch], frame[ch], taps);
      const auto a = static_cast<double>(gen.activation(ch, static_cast<float>(t - delay)));
      const double rms =
          std::hypot(a * static_cast<double>(spec.mvc_rms_counts * gen.channel_gain(ch)) * emg_gain, noise_rms);
      got[ch] += static_cast<double>(env);
      want[ch] += std::sqrt(2.0 / kPi) * rms;
    }
    if ((k + 1) % 2000 == 0) {
      if (t > 1.5 && t < 9.5) {
        for (std::size_t ch = 0; ch < kChannels; ++ch) {
          INFO("t " << t << " ch " << ch << " envelope " << got[ch] / 2000 << " expected " << want[ch] / 2000);
          CHECK(got[ch] == doctest::Approx(want[ch]).epsilon(0.15));
          got_all += got[ch];
          want_all += want[ch];
          ++checked;
        }
      }
      got.fill(0.0);
      want.fill(0.0);
    }
  }
  CHECK(checked >= 32);
  MESSAGE("synthetic envelope / known envelope over the ramp: " << got_all / want_all);
  CHECK(got_all / want_all == doctest::Approx(1.0).epsilon(0.03));
}

TEST_CASE("reported group delay is the delay of the envelope's step response") {
  const ChainModel m = design_chain(config_at(2000));
  const ChainDelay d = chain_group_delay(m);
  CHECK(d.envelope_s == doctest::Approx(0.1).epsilon(0.01));
  CHECK(d.filters_s > 0.0);
  CHECK(d.filters_s < 0.01);
  // A 130 Hz burst switched on at t0: the linear envelope (a first-order lag)
  // reaches 1 - 1/e of its final value one time constant after the filters' delay.
  ChannelState s;
  ChainTaps taps;
  const double fs = 2000.0, t0 = 1.0;
  double final_env = 0.0, t63 = -1.0;
  std::vector<float> env;
  for (int k = 0; k < static_cast<int>(3.0 * fs); ++k) {
    const double t = k / fs;
    const double x = 2048.0 + (t >= t0 ? 500.0 * std::sin(2.0 * kPi * 130.0 * t) : 0.0);
    env.push_back(chain_step(m, s, static_cast<float>(x), taps));
  }
  final_env = static_cast<double>(env.back());
  for (std::size_t k = 0; k < env.size(); ++k) {
    const double t = static_cast<double>(k) / fs;
    if (t > t0 && static_cast<double>(env[k]) >= (1.0 - std::exp(-1.0)) * final_env) {
      t63 = t - t0;
      break;
    }
  }
  CHECK(t63 == doctest::Approx(d.total_s()).epsilon(0.05));
}

TEST_CASE("moving RMS envelope of a sine is amplitude / sqrt 2") {
  proto::DeviceConfig cfg = config_at(2000);
  cfg.envelope_mode = proto::EnvelopeMode::moving_rms;
  cfg.envelope_tau_ms = 250;
  const ChainModel m = design_chain(cfg);
  CHECK(m.rms_slots * m.rms_slot_samples >= 500);
  CHECK(m.rms_slots * m.rms_slot_samples < 500 + m.rms_slot_samples);
  ChannelState s;
  ChainTaps taps;
  float env = 0.0F;
  for (int k = 0; k < 4000; ++k) {
    env = chain_step(m, s, static_cast<float>(2048.0 + 300.0 * std::sin(2.0 * kPi * 130.0 * k / 2000.0)), taps);
  }
  CHECK(env == doctest::Approx(300.0 / std::sqrt(2.0)).epsilon(0.02));
  // Its delay is about half the window.
  CHECK(chain_group_delay(m).envelope_s == doctest::Approx(0.125).epsilon(0.05));
}
