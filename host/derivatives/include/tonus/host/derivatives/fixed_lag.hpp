// Fixed-lag (streaming) smoothing: fed one sample at a time, returns position,
// velocity and acceleration of the sample `lag` frames behind, smoothed with
// the samples that arrived since (bounded look-ahead, lag * dt of latency).
//
// It runs the batch Kalman filter forward and, at each push, the RTS backward
// pass over the last `lag` steps, so its output for sample k - lag is exactly
// what batch Method::kalman gives at k - lag for the series x[0..k] (to
// rounding); against the batch result of the whole series the difference is the
// information the samples after k carry, which decays with the lag (measured in
// docs/derivatives.md, fc = 6 Hz: 1/6 s of lag, 5 frames at 30 Hz or 20 at
// 120 Hz, brings it within 10 % of the batch's own noise; 1/12 s within ~30 %).
// The output is the smoother's own states (Method::kalman): a cubic spline
// needs the whole series; in the interior they differ from kalman_spline by
// less than a tenth of the noise at 120 Hz (docs/derivatives.md).
//
// Missing samples (NaN, infinity) and the outlier gate behave as in batch.
// No allocation after create(); cost O(lag) per push (a 3x3 matrix-vector
// product per frame of lag) plus one filter step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <span>

#include "tonus/host/derivatives/params.hpp"
#include "tonus/host/derivatives/white_jerk.hpp"

namespace tonus::derivatives {

struct Estimate {
  bool valid = false;     // false until 3 finite samples arrived and `lag` frames passed
  std::size_t index = 0;  // which sample (0 = the first pushed) this estimate is for
  double pos = 0.0;
  double vel = 0.0;
  double acc = 0.0;
};

class FixedLag {
 public:
  // Largest lag kept (1 s at 120 Hz); the storage is fixed, about 100 bytes a frame.
  static constexpr std::size_t kMaxLag = 120;

  struct Created;
  // Validates params (method must be kalman or kalman_spline; both give the
  // smoother's states here), dt_s and lag <= kMaxLag.
  static Created create(double dt_s, const Params& params, std::size_t lag);

  // Feeds the next sample (NaN = missing) and returns the estimate for the
  // sample `lag` frames before it.
  Estimate push(double x);

  // The current estimate for the sample `frames_back` frames before the last
  // one pushed, smoothed with everything pushed so far: frames_back = 0 is the
  // filter, = lag what push() returned. At the end of a stream, frames_back =
  // lag - 1 .. 0 give the remaining samples, equal to the batch result.
  // Invalid if frames_back > lag or reaches before the first sample.
  [[nodiscard]] Estimate estimate(std::size_t frames_back) const;
  // estimate(j) for j = 0 .. out.size() - 1 into out[j], in one backward pass
  // (the same arithmetic, so the same bits, at the cost of one estimate of the
  // deepest).
  void estimate_window(std::span<Estimate> out) const;

  // Forgets every sample (keeps the parameters).
  void reset();

  [[nodiscard]] std::size_t lag() const { return lag_; }
  [[nodiscard]] std::size_t pushed() const { return pushed_; }
  [[nodiscard]] std::size_t missing() const { return missing_; }
  [[nodiscard]] std::size_t rejected() const { return rejected_; }

 private:
  FixedLag() = default;

  std::size_t lag_ = 0;
  WhiteJerkFilter filter_;
  // Links of the last kMaxLag steps: step k's at k % kMaxLag.
  std::array<RtsLink, kMaxLag> links_{};
  std::size_t pushed_ = 0;
  std::size_t missing_ = 0;
  std::size_t rejected_ = 0;
};

struct FixedLag::Created {
  Status status;
  std::optional<FixedLag> smoother;
  explicit operator bool() const { return status.ok(); }
};

// Three independent FixedLag, one per coordinate of a point.
struct Estimate3 {
  bool valid = false;
  std::size_t index = 0;
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  Eigen::Vector3d vel = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();
};

class FixedLag3 {
 public:
  struct Created;
  static Created create(double dt_s, const Params& params, std::size_t lag);
  Estimate3 push(const Eigen::Vector3d& x);
  [[nodiscard]] Estimate3 estimate(std::size_t frames_back) const;
  // As FixedLag::estimate_window, per coordinate.
  void estimate_window(std::span<Estimate3> out) const;
  void reset();
  [[nodiscard]] const FixedLag& coordinate(std::size_t c) const { return axes_[c]; }

 private:
  explicit FixedLag3(const FixedLag& one) : axes_{one, one, one} {}
  std::array<FixedLag, 3> axes_;
};

struct FixedLag3::Created {
  Status status;
  std::optional<FixedLag3> smoother;
  explicit operator bool() const { return status.ok(); }
};

}  // namespace tonus::derivatives
