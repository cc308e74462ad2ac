// Parameters, methods and errors of tonus::derivatives, and how the smoother's
// two numbers (measurement noise, cutoff) map to the Kalman model.
//
// The model (docs/derivatives.md): each coordinate is a constant-acceleration
// state [p, v, a] driven by white jerk of spectral density q, observed as
// p + white noise of standard deviation sigma every dt. The RTS smoother of this
// model is, in the interior of a long series, a zero-phase low-pass filter of
// gain 1 / (1 + (f / f_c)^6) (for f_c well below Nyquist) with
//     q = sigma^2 * dt * (2 pi f_c)^6,
// so the smoothing is chosen by the cutoff f_c (the -6 dB frequency) and the
// smoothed values depend on f_c and dt only; sigma matters for the outlier gate
// and the predicted noise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace tonus::derivatives {

enum class Method : std::uint8_t {
  kalman_spline,      // RTS-smoothed positions, cubic spline through them, differentiated analytically
  kalman,             // the smoother's own velocity and acceleration states
  spline,             // cubic spline through the raw samples (no smoothing)
  finite_difference,  // central differences, second-order one-sided at the ends (baseline)
};

enum class SplineEnd : std::uint8_t {
  not_a_knot,  // third derivative continuous at the second and last-but-one knot: exact for cubics
  natural,     // zero second derivative at both ends: forces a = 0 there (see docs)
};

// Fewest samples any method accepts (a not-a-knot cubic needs 4 knots).
inline constexpr std::size_t kMinSamples = 4;
// The Kalman methods need this many finite samples (the state has 3 components).
inline constexpr std::size_t kMinFiniteSamples = 3;
// Accepted range of 2 pi f_c dt (the cutoff in radians per sample): outside it
// the smoother is either a global quadratic fit or an interpolator.
inline constexpr double kMinCutoffRadPerSample = 1e-3;
inline constexpr double kMaxCutoffRadPerSample = 1e3;

struct Params {
  Method method = Method::kalman_spline;
  // Standard deviation of the measurement noise, in the units of the samples
  // (2 mm: optical mocap after skeleton fitting). Used by the outlier gate and
  // predicted_noise(); the smoothed values do not depend on it.
  double noise_sigma = 0.002;
  // -6 dB frequency of the smoother, Hz. 6 Hz passes motion below 2.5 Hz within
  // 0.5 % and below 3.7 Hz within 5 %, and is near the best for a brisk foot
  // step (0.5 m in 0.5 s) under 2 mm noise at 60..240 Hz; postural sway prefers
  // 4 Hz, kicks and impacts 8-12 Hz, at the price of acceleration noise growing
  // as fc^2.5 (predicted_noise(); docs/derivatives.md has the table).
  double cutoff_hz = 6.0;
  SplineEnd spline_end = SplineEnd::not_a_knot;
  // Kalman methods: a finite sample whose innovation (distance from the filter's
  // prediction) exceeds outlier_gate times its predicted standard deviation is
  // treated as missing (a fitting glitch, a marker swap). 0 turns the gate off.
  // The causal filter lags jerky motion by about jerk / (2 pi fc)^3, several
  // deviations for a kick: use 20 or more (20 x 2 mm: glitches beyond ~4 cm),
  // which stays quiet on the test motions at 30..240 Hz. At most kMaxGatedRun
  // samples in a row are rejected; the next is accepted, so a real jump is
  // followed after a few rejected runs.
  double outlier_gate = 0.0;
};

inline constexpr std::size_t kMaxGatedRun = 3;

enum class Error : std::uint8_t {
  none,
  too_few_samples,         // fewer than kMinSamples
  too_few_finite_samples,  // Kalman methods: fewer than kMinFiniteSamples finite samples
  non_finite_sample,       // spline, finite_difference: a NaN or infinity at Status::index
  bad_dt,                  // dt not finite or not > 0
  bad_noise_sigma,         // not finite or not > 0
  bad_cutoff,              // not finite, not > 0, or 2 pi f_c dt outside the accepted range
  bad_outlier_gate,        // not finite or < 0
  bad_method,              // not one of the enumerators (or not available here)
  bad_spline_end,          // not one of the enumerators
  bad_lag,                 // fixed-lag: lag > FixedLag::kMaxLag, or asked further back than kept
  bad_view,                // a view with a null pointer, or an output of another size or of stride 0
};
std::string_view to_string(Error e);

// An error and, where it concerns one sample, its index.
struct Status {
  Error error = Error::none;
  std::size_t index = 0;
  [[nodiscard]] bool ok() const { return error == Error::none; }
  explicit operator bool() const { return ok(); }
};

// Checks every parameter for a series of n samples at dt_s.
Status validate(const Params& params, double dt_s, std::size_t n);

// The white-jerk spectral density (units^2 / s^5) that puts the smoother's
// -6 dB point at cutoff_hz, and its inverse.
double jerk_psd(double noise_sigma, double cutoff_hz, double dt_s);
double cutoff_from_jerk_psd(double jerk_psd, double noise_sigma, double dt_s);

// RMS error that white measurement noise of noise_sigma leaves in the smoothed
// position, velocity and acceleration in the interior of a long series
// (continuous-time limit, within a few % while f_c < rate / 6):
//   pos: sigma sqrt(5 w dt / 18), vel: sigma sqrt(w^3 dt / 12), acc: sigma sqrt(w^5 dt / 18), w = 2 pi f_c.
struct NoiseRms {
  double pos = 0.0;
  double vel = 0.0;
  double acc = 0.0;
};
NoiseRms predicted_noise(const Params& params, double dt_s);

}  // namespace tonus::derivatives
