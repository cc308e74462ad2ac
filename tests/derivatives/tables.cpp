#include "tables.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tonus/host/derivatives/batch.hpp"

namespace tonus::derivatives::test {

std::string name(Method m) {
  switch (m) {
    case Method::kalman_spline: return "kalman_spline";
    case Method::kalman: return "kalman";
    case Method::spline: return "spline";
    case Method::finite_difference: return "finite_difference";
  }
  return "?";
}

Errors signal_errors(Method m, const Signal& s, double rate_hz, double seconds, const Params& base) {
  const double dt = 1.0 / rate_hz;
  const auto n = static_cast<std::size_t>(std::lround(seconds * rate_hz)) + 1;
  const auto ends = static_cast<std::size_t>(std::lround(kEndSeconds * rate_hz));
  Params p = base;
  p.method = m;
  const Result r = differentiate(sample(s, n, dt), dt, p);
  const Pva t = truth(s, n, dt);
  Errors e;
  if (!r) return {1e300, 1e300, 1e300, 1e300};
  e.vel_interior = max_error(r.vel, t.v, ends, n - ends);
  e.acc_interior = max_error(r.acc, t.a, ends, n - ends);
  e.vel_ends = std::max(max_error(r.vel, t.v, 0, ends), max_error(r.vel, t.v, n - ends, n));
  e.acc_ends = std::max(max_error(r.acc, t.a, 0, ends), max_error(r.acc, t.a, n - ends, n));
  return e;
}

Errors sinusoid_errors(Method m, double rate_hz, double freq_hz, const Params& base) {
  // Worst over eight phases: the error at the ends depends on where the cycle is.
  const double w = 2.0 * std::numbers::pi * freq_hz;
  Errors worst;
  for (int i = 0; i < 8; ++i) {
    const Errors e = signal_errors(m, sinusoid(1.0, freq_hz, std::numbers::pi * i / 8.0), rate_hz, 4.0, base);
    worst.vel_interior = std::max(worst.vel_interior, e.vel_interior / w);
    worst.vel_ends = std::max(worst.vel_ends, e.vel_ends / w);
    worst.acc_interior = std::max(worst.acc_interior, e.acc_interior / (w * w));
    worst.acc_ends = std::max(worst.acc_ends, e.acc_ends / (w * w));
  }
  return worst;
}

NoiseGain measured_noise_gain(Method m, double rate_hz, double sigma, std::uint64_t seed, const Params& base) {
  const double dt = 1.0 / rate_hz;
  constexpr std::size_t kN = 20000;
  const std::size_t ends = static_cast<std::size_t>(std::lround(kEndSeconds * rate_hz));
  std::vector<double> y(kN, 0.0);
  add_noise(y, sigma, seed);
  Params p = base;
  p.method = m;
  p.noise_sigma = sigma;
  const Result r = differentiate(y, dt, p);
  if (!r) return {1e300, 1e300};
  const std::vector<double> zero(kN, 0.0);
  return {rms_error(r.vel, zero, ends, kN - ends) / sigma, rms_error(r.acc, zero, ends, kN - ends) / sigma};
}

}  // namespace tonus::derivatives::test
