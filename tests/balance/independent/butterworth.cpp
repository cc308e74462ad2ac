#include "independent/butterworth.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tonus::indep {

Biquad butterworth_lowpass(double cutoff_hz, double sample_rate_hz) {
  // s / wc = (1 / K) (1 - z^-1) / (1 + z^-1) with K = tan(pi fc / fs), then
  // both sides times K^2 (1 + z^-1)^2.
  const double k = std::tan(std::numbers::pi * cutoff_hz / sample_rate_hz);
  const double a0 = 1.0 + std::numbers::sqrt2 * k + k * k;
  Biquad f;
  f.b0 = k * k / a0;
  f.b1 = 2.0 * f.b0;
  f.b2 = f.b0;
  f.a1 = 2.0 * (k * k - 1.0) / a0;
  f.a2 = (1.0 - std::numbers::sqrt2 * k + k * k) / a0;
  return f;
}

double butterworth_power_gain(double frequency_hz, double cutoff_hz, double sample_rate_hz) {
  const double r = std::tan(std::numbers::pi * frequency_hz / sample_rate_hz) /
                   std::tan(std::numbers::pi * cutoff_hz / sample_rate_hz);
  return 1.0 / (1.0 + r * r * r * r);
}

namespace {

// Direct form II transposed, in place, starting from the steady state of a
// constant input equal to x[0] (so a constant signal passes untouched).
void run(const Biquad& f, std::vector<double>& x) {
  const double dc = (f.b0 + f.b1 + f.b2) / (1.0 + f.a1 + f.a2);
  double z1 = (dc - f.b0) * x.front();
  double z2 = (f.b2 - f.a2 * dc) * x.front();
  for (double& v : x) {
    const double in = v;
    const double out = f.b0 * in + z1;
    z1 = f.b1 * in - f.a1 * out + z2;
    z2 = f.b2 * in - f.a2 * out;
    v = out;
  }
}

}  // namespace

std::vector<double> filtfilt(const Biquad& filter, std::span<const double> x) {
  const std::size_t n = x.size();
  if (n < 2) return {x.begin(), x.end()};
  const std::size_t pad = std::min<std::size_t>(9, n - 1);
  std::vector<double> ext;
  ext.reserve(n + 2 * pad);
  for (std::size_t k = pad; k >= 1; --k) ext.push_back(2.0 * x[0] - x[k]);
  ext.insert(ext.end(), x.begin(), x.end());
  for (std::size_t k = 1; k <= pad; ++k) ext.push_back(2.0 * x[n - 1] - x[n - 1 - k]);
  run(filter, ext);
  std::reverse(ext.begin(), ext.end());
  run(filter, ext);
  std::reverse(ext.begin(), ext.end());
  const auto first = ext.begin() + static_cast<std::ptrdiff_t>(pad);
  return {first, first + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace tonus::indep
