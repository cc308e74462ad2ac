// A second-order Butterworth low-pass and its zero-lag (forward-backward)
// application, as MATLAB's and SciPy's filtfilt do it.
#pragma once

#include <span>
#include <vector>

namespace tonus::indep {

// y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2]
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

// The analog prototype wc^2 / (s^2 + sqrt(2) wc s + wc^2) through the
// bilinear transform, wc prewarped so the digital gain at cutoff_hz is
// exactly 1/sqrt(2). Needs 0 < cutoff_hz < sample_rate_hz / 2.
[[nodiscard]] Biquad butterworth_lowpass(double cutoff_hz, double sample_rate_hz);

// |H(f)|^2 of the digital filter: 1 / (1 + (tan(pi f/fs) / tan(pi fc/fs))^4).
// filtfilt's gain is this (not its square root): the signal passes twice.
[[nodiscard]] double butterworth_power_gain(double frequency_hz, double cutoff_hz, double sample_rate_hz);

// The filter run forward, then backward over the result: zero phase, gain
// |H|^2. The ends are padded with odd reflections (2 x[0] - x[k]) of
// 3 * 3 samples (SciPy's default length; fewer if the signal is shorter) and
// each pass starts from the filter's steady state for its first sample, as
// SciPy's filtfilt does. Signals of fewer than 2 samples come back unchanged.
[[nodiscard]] std::vector<double> filtfilt(const Biquad& filter, std::span<const double> x);

}  // namespace tonus::indep
