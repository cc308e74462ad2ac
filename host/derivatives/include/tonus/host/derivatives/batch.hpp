// Batch (offline) smoothing and differentiation of a uniformly sampled series:
// position, velocity and acceleration at every sample, by the method in
// Params (default kalman_spline: RTS-smoothed positions, then a cubic spline
// through them, differentiated analytically).
//
// Accuracy (docs/derivatives.md has the tables): in the interior the Kalman
// methods attenuate content at f by (f/fc)^6 / (1 + (f/fc)^6) and leave
// sigma * sqrt(w^5 dt / 18) of acceleration noise (w = 2 pi fc; 0.38 m/s^2 for
// 2 mm at 120 Hz); within ~0.15 s of either end they see one side only and
// err by up to 2 J tau in acceleration and 2 J tau^2 in velocity (J: the jerk
// there, tau = 1 / w), nothing if the motion is at rest there.
//
// Missing samples: with the Kalman methods a NaN or infinite sample is missing
// data (a mocap gap): the filter skips its update and the smoother bridges the
// gap (a quintic-like curve that joins both sides with continuous p, v, a);
// Stats reports how many and the longest run, so the caller can refuse long
// gaps. The spline and finite-difference methods need every sample and report
// the first non-finite one (Error::non_finite_sample with its index).
//
// Errors are values (Status); nothing throws except std::bad_alloc. Outputs
// are written only when the status is ok.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "tonus/host/derivatives/params.hpp"
#include "tonus/host/derivatives/strided.hpp"

namespace tonus::derivatives {

struct Stats {
  std::size_t missing = 0;      // non-finite samples skipped (Kalman methods)
  std::size_t longest_gap = 0;  // longest run of missing samples
  std::size_t rejected = 0;     // finite samples rejected by the outlier gate
};

// Where to write the results; each view may be empty (size 0) to skip it,
// otherwise it must hold as many elements as the input. Outputs may alias the
// input (it is copied first), not each other.
struct Outputs {
  Strided<double> pos = {};
  Strided<double> vel = {};
  Strided<double> acc = {};
};

// The core entry point: x[i] sampled at i * dt_s. Allocates scratch of about
// 12 doubles per sample for the Kalman methods, 1 per sample for the splines.
Status differentiate(Strided<const double> x, double dt_s, const Params& params, const Outputs& out,
                     Stats* stats = nullptr);

// Convenience: a contiguous scalar series, results in vectors.
struct Result {
  Status status;
  Stats stats;
  std::vector<double> pos, vel, acc;
  explicit operator bool() const { return status.ok(); }
};
Result differentiate(std::span<const double> x, double dt_s, const Params& params = {});

// Convenience: a series of points, each coordinate processed independently.
// Stats add up over the coordinates (a NaN point counts three times; the
// longest gap is the longest of any coordinate); the status index is the sample's.
struct Result3 {
  Status status;
  Stats stats;
  std::vector<Eigen::Vector3d> pos, vel, acc;
  explicit operator bool() const { return status.ok(); }
};
Result3 differentiate(std::span<const Eigen::Vector3d> points, double dt_s, const Params& params = {});

}  // namespace tonus::derivatives
