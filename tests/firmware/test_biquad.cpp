// Filter designs against closed-form responses: Butterworth magnitude
// 1/sqrt(1 + Omega^2n), the analog notch (s^2+1)/(s^2+s/Q+1) through the
// bilinear map, and the group delay against a numerical phase derivative.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "tonus/firmware/biquad.hpp"

using namespace tonus::fw;

namespace {

constexpr double kPi = std::numbers::pi;

// Prewarped normalised frequency of the bilinear transform.
double omega(double f, double f0, double fs) { return std::tan(kPi * f / fs) / std::tan(kPi * f0 / fs); }

std::complex<double> response(const Biquad& c, double f, double fs) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * kPi * f / fs);
  return (double{c.b0} + double{c.b1} * z1 + double{c.b2} * z1 * z1) /
         (1.0 + double{c.a1} * z1 + double{c.a2} * z1 * z1);
}

// Steady-state amplitude of a unit sine run through the sections with biquad_step.
double simulated_gain(const Biquad* sections, std::size_t n, double f, double fs) {
  BiquadState s[4]{};
  const auto total = static_cast<int>(fs * 4.0);
  double peak = 0.0;
  for (int k = 0; k < total; ++k) {
    auto y = static_cast<float>(std::sin(2.0 * kPi * f * k / fs));
    for (std::size_t j = 0; j < n; ++j) y = biquad_step(sections[j], s[j], y);
    if (k > total / 2) peak = std::max(peak, std::fabs(static_cast<double>(y)));
  }
  return peak;
}

}  // namespace

TEST_CASE("Butterworth Q values of a 4th-order cascade") {
  CHECK(butterworth_q(4, 1) == doctest::Approx(0.5411961).epsilon(1e-6));
  CHECK(butterworth_q(4, 0) == doctest::Approx(1.3065630).epsilon(1e-6));
  CHECK(butterworth_q(2, 0) == doctest::Approx(std::sqrt(0.5)).epsilon(1e-9));
}

TEST_CASE("4th-order Butterworth low-pass matches 1/sqrt(1+Omega^8)") {
  for (double fs : {1000.0, 2000.0, 4000.0}) {
    const double fc = 450.0 < 0.45 * fs ? 450.0 : 0.3 * fs;
    const Biquad s[2] = {design_lowpass(fs, fc, butterworth_q(4, 0)), design_lowpass(fs, fc, butterworth_q(4, 1))};
    for (int k = 0; 5.0 + k * fs / 97.0 < 0.49 * fs; ++k) {
      const double f = 5.0 + k * fs / 97.0;
      const double w = omega(f, fc, fs);
      const double expected = 1.0 / std::sqrt(1.0 + std::pow(w, 8.0));
      const double got = magnitude(s[0], f, fs) * magnitude(s[1], f, fs);
      CHECK(got == doctest::Approx(expected).epsilon(2e-4).scale(1.0));
    }
    CHECK(magnitude(s[0], fc, fs) * magnitude(s[1], fc, fs) == doctest::Approx(std::sqrt(0.5)).epsilon(1e-4));
  }
}

TEST_CASE("4th-order Butterworth high-pass at 20 Hz: passband, corner, stopband") {
  const double fs = 2000.0;
  const Biquad s[2] = {design_highpass(fs, 20.0, butterworth_q(4, 0)), design_highpass(fs, 20.0, butterworth_q(4, 1))};
  for (double f : {2.0, 5.0, 10.0, 20.0, 40.0, 80.0, 200.0, 600.0}) {
    const double w = omega(f, 20.0, fs);
    const double expected = std::pow(w, 4.0) / std::sqrt(1.0 + std::pow(w, 8.0));
    CHECK(magnitude(s[0], f, fs) * magnitude(s[1], f, fs) == doctest::Approx(expected).epsilon(1e-3).scale(1e-3));
  }
  // Stopband: -24 dB per octave, so 5 Hz is below -47 dB; passband flat.
  CHECK(20.0 * std::log10(magnitude(s[0], 5.0, fs) * magnitude(s[1], 5.0, fs)) < -47.0);
  CHECK(magnitude(s[0], 100.0, fs) * magnitude(s[1], 100.0, fs) == doctest::Approx(1.0).epsilon(1e-3));
  // The float DF2T run reproduces the design's magnitude.
  for (double f : {10.0, 20.0, 60.0}) {
    CHECK(simulated_gain(s, 2, f, fs) ==
          doctest::Approx(magnitude(s[0], f, fs) * magnitude(s[1], f, fs)).epsilon(5e-3));
  }
}

TEST_CASE("notch: the closed form, depth, and a 4 Hz width on every harmonic the band uses") {
  // Orfanidis 11.3: |H(w)|^2 = (cos w - cos w0)^2 / ((cos w - cos w0)^2 + tan^2(dw/2) sin^2 w),
  // whose -3 dB points are dw apart; dw = 2 pi bw / fs.
  const double bw = 4.0;
  for (const double fs : {1000.0, 2000.0}) {
    for (const double mains : {50.0, 60.0}) {
      for (int h = 1; h <= 4 && h * mains + bw < fs / 2.0; ++h) {
        const double f0 = h * mains;
        INFO("fs " << fs << " notch " << f0);
        const Biquad n = design_notch(fs, f0, bw);
        const double w0 = 2.0 * std::numbers::pi * f0 / fs, beta = std::tan(std::numbers::pi * bw / fs);
        for (const double df : {-30.0, -2.0, -0.5, 0.5, 2.0, 30.0}) {
          const double w = 2.0 * std::numbers::pi * (f0 + df) / fs;
          const double d = std::cos(w) - std::cos(w0);
          const double expected = std::fabs(d) / std::sqrt(d * d + beta * beta * std::sin(w) * std::sin(w));
          CHECK(magnitude(n, f0 + df, fs) == doctest::Approx(expected).epsilon(1e-3).scale(1e-3));
        }
        // -3 dB points bw apart (the documented 4 Hz), found numerically.
        double lo = f0, hi = f0;
        while (magnitude(n, lo, fs) < std::sqrt(0.5)) lo -= 0.0005;
        while (magnitude(n, hi, fs) < std::sqrt(0.5)) hi += 0.0005;
        CHECK(hi - lo == doctest::Approx(bw).epsilon(0.01));
        // Mains drift of 0.2 Hz is still rejected by more than 18 dB (the documented claim), run in float.
        const Biquad s[1] = {n};
        CHECK(20.0 * std::log10(simulated_gain(s, 1, f0 - 0.2, fs)) < -18.0);
        CHECK(20.0 * std::log10(simulated_gain(s, 1, f0 + 0.2, fs)) < -18.0);
        CHECK(20.0 * std::log10(simulated_gain(s, 1, f0, fs)) < -40.0);
      }
    }
  }
}

TEST_CASE("group delay equals the numerical derivative of the phase") {
  const double fs = 2000.0;
  const Biquad cases[] = {design_highpass(fs, 20.0, 0.54), design_lowpass(fs, 450.0, 1.31), design_notch(fs, 50.0, 4.0),
                          design_lowpass(fs, 5.0, 0.7071)};
  for (const Biquad& c : cases) {
    for (double f : {3.0, 30.0, 80.0, 230.0, 700.0}) {
      const double h = 1e-4;
      const double w1 = 2.0 * kPi * (f - h) / fs, w2 = 2.0 * kPi * (f + h) / fs;
      double dphi = std::arg(response(c, f + h, fs)) - std::arg(response(c, f - h, fs));
      while (dphi > kPi) dphi -= 2.0 * kPi;
      while (dphi < -kPi) dphi += 2.0 * kPi;
      const double numeric = -dphi / (w2 - w1);
      CHECK(group_delay_samples(c, f, fs) == doctest::Approx(numeric).epsilon(1e-4).scale(1.0));
    }
  }
}
