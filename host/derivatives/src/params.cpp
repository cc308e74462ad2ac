#include "tonus/host/derivatives/params.hpp"

#include <cmath>
#include <numbers>

namespace tonus::derivatives {

std::string_view to_string(Error e) {
  switch (e) {
    case Error::none: return "none";
    case Error::too_few_samples: return "too_few_samples";
    case Error::too_few_finite_samples: return "too_few_finite_samples";
    case Error::non_finite_sample: return "non_finite_sample";
    case Error::bad_dt: return "bad_dt";
    case Error::bad_noise_sigma: return "bad_noise_sigma";
    case Error::bad_cutoff: return "bad_cutoff";
    case Error::bad_outlier_gate: return "bad_outlier_gate";
    case Error::bad_method: return "bad_method";
    case Error::bad_spline_end: return "bad_spline_end";
    case Error::bad_lag: return "bad_lag";
    case Error::bad_view: return "bad_view";
  }
  return "unknown";
}

Status validate(const Params& params, double dt_s, std::size_t n) {
  const auto fail = [](Error e) { return Status{e, 0}; };
  switch (params.method) {
    case Method::kalman_spline:
    case Method::kalman:
    case Method::spline:
    case Method::finite_difference: break;
    default: return fail(Error::bad_method);
  }
  switch (params.spline_end) {
    case SplineEnd::not_a_knot:
    case SplineEnd::natural: break;
    default: return fail(Error::bad_spline_end);
  }
  if (!std::isfinite(dt_s) || dt_s <= 0.0) return fail(Error::bad_dt);
  if (!std::isfinite(params.noise_sigma) || params.noise_sigma <= 0.0) return fail(Error::bad_noise_sigma);
  if (!std::isfinite(params.cutoff_hz) || params.cutoff_hz <= 0.0) return fail(Error::bad_cutoff);
  const double rad_per_sample = 2.0 * std::numbers::pi * params.cutoff_hz * dt_s;
  if (!(rad_per_sample >= kMinCutoffRadPerSample && rad_per_sample <= kMaxCutoffRadPerSample)) {
    return fail(Error::bad_cutoff);
  }
  if (!std::isfinite(params.outlier_gate) || params.outlier_gate < 0.0) return fail(Error::bad_outlier_gate);
  if (n < kMinSamples) return fail(Error::too_few_samples);
  return {};
}

double jerk_psd(double noise_sigma, double cutoff_hz, double dt_s) {
  const double w = 2.0 * std::numbers::pi * cutoff_hz;
  return noise_sigma * noise_sigma * dt_s * std::pow(w, 6.0);
}

double cutoff_from_jerk_psd(double jerk_psd, double noise_sigma, double dt_s) {
  return std::pow(jerk_psd / (noise_sigma * noise_sigma * dt_s), 1.0 / 6.0) / (2.0 * std::numbers::pi);
}

NoiseRms predicted_noise(const Params& params, double dt_s) {
  const double w = 2.0 * std::numbers::pi * params.cutoff_hz;
  const double s = params.noise_sigma;
  return {s * std::sqrt(5.0 * w * dt_s / 18.0), s * std::sqrt(w * w * w * dt_s / 12.0),
          s * std::sqrt(std::pow(w, 5.0) * dt_s / 18.0)};
}

}  // namespace tonus::derivatives
