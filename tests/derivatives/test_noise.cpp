// Noise amplification: RMS acceleration error per unit of measurement noise,
// per method, against the exact discrete prediction and the closed form, and
// the margin by which smoothing beats the unsmoothed methods.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "reference.hpp"
#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

TEST_CASE("measured noise gain matches the exact response's and the closed form") {
  const Params p{};
  for (double rate : kRates) {
    const double dt = 1.0 / rate;
    const double q = jerk_psd(p.noise_sigma, p.cutoff_hz, dt);
    const Rms exact_k = noise_gain([&](double th) { return kalman_response(th, dt, p.noise_sigma, q); });
    const Rms exact_ks = noise_gain([&](double th) { return kalman_spline_response(th, dt, p.noise_sigma, q); });
    const Rms exact_s = noise_gain([&](double th) { return spline_response(th, dt); });
    const Rms exact_fd = noise_gain([&](double th) { return finite_difference_response(th, dt); });
    const NoiseRms closed = predicted_noise(Params{.noise_sigma = 1.0}, dt);
    CAPTURE(rate);
    const auto near = [](double measured, double expected) {
      return std::abs(measured / expected - 1.0) < 0.05;  // 20,000 samples: ~1-2 % sampling scatter
    };
    const NoiseGain k = measured_noise_gain(Method::kalman, rate, 0.002, 11);
    const NoiseGain ks = measured_noise_gain(Method::kalman_spline, rate, 0.002, 11);
    const NoiseGain s = measured_noise_gain(Method::spline, rate, 0.002, 11);
    const NoiseGain fd = measured_noise_gain(Method::finite_difference, rate, 0.002, 11);
    CHECK(near(k.acc, exact_k.a));
    CHECK(near(k.vel, exact_k.v));
    CHECK(near(ks.acc, exact_ks.a));
    CHECK(near(s.acc, exact_s.a));
    CHECK(near(fd.acc, exact_fd.a));
    CHECK(near(fd.acc, std::sqrt(6.0) / (dt * dt)));  // (1, -2, 1) / dt^2
    // The closed form (continuous limit) is within 3 % down to 30 Hz at fc = 6 Hz.
    CHECK(std::abs(closed.acc / exact_k.a - 1.0) < 0.03);
    CHECK(std::abs(closed.vel / exact_k.v - 1.0) < 0.03);
    CHECK(std::abs(closed.pos / exact_k.p - 1.0) < 0.03);
  }
}

TEST_CASE("smoothing beats the raw spline and differences by a wide margin") {
  // Differences amplify noise by sqrt(6) / dt^2, the smoother by ~sqrt(w^5 dt / 18): the margin grows as
  // (w dt)^-2.5, from ~5x at 30 Hz to ~500x at 240 Hz for fc = 6 Hz.
  for (double sigma : {0.001, 0.002, 0.005}) {
    for (double rate : kRates) {
      const double wdt = 2.0 * std::numbers::pi * Params{}.cutoff_hz / rate;
      const double margin = 0.8 * std::sqrt(108.0) * std::pow(wdt, -2.5);
      const auto seed = static_cast<std::uint64_t>(rate + 1000 * sigma);
      const NoiseGain ks = measured_noise_gain(Method::kalman_spline, rate, sigma, seed);
      const NoiseGain s = measured_noise_gain(Method::spline, rate, sigma, seed);
      const NoiseGain fd = measured_noise_gain(Method::finite_difference, rate, sigma, seed);
      CAPTURE(sigma);
      CAPTURE(rate);
      CHECK(fd.acc > margin * ks.acc);
      CHECK(s.acc > fd.acc);  // the spline's second derivative is the noisier one
      CHECK(fd.vel > 1.5 * ks.vel);
      if (rate >= 120) CHECK(fd.acc > 100.0 * ks.acc);
    }
  }
}

TEST_CASE("the smoothed values do not depend on sigma (only on fc and dt)") {
  std::vector<double> y(200);
  add_noise(y, 0.003, 5);
  const Result a = differentiate(y, 0.01, Params{.noise_sigma = 0.001});
  const Result b = differentiate(y, 0.01, Params{.noise_sigma = 0.05});
  for (std::size_t i = 0; i < y.size(); ++i) CHECK(a.acc[i] == doctest::Approx(b.acc[i]).epsilon(1e-9).scale(1.0));
}
