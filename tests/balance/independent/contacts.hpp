// Whether a foot point is on the ground: low and slow, with hysteresis.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace tonus::indep {

struct ContactOptions {
  // A point lands when within enter_height_m of its resting height and
  // slower than enter_speed_mps; it stays down until it rises leave_height_m
  // or moves at leave_speed_mps.
  double enter_height_m = 0.02;
  double leave_height_m = 0.03;
  double enter_speed_mps = 0.4;
  double leave_speed_mps = 0.8;
  // The resting height is a low percentile of the point's heights within a
  // window around the frame, so a floor that creeps is followed (the CMU
  // walk's rises about 4 cm in 2.9 s): a point must be down for more than
  // the percentile's share of each window for that height to be the floor's.
  double window_s = 1.0;
  double rest_percentile = 0.05;
};

// The `percentile` (0..1) of the finite values of x within half_window
// samples of each sample; NaN where there is none.
[[nodiscard]] std::vector<double> rolling_percentile(std::span<const double> x, std::size_t half_window,
                                                     double percentile);

// Contact per frame from a point's height, resting height and speed. A
// non-finite value lifts the point.
[[nodiscard]] std::vector<bool> detect_contact(std::span<const double> height, std::span<const double> rest,
                                               std::span<const double> speed, const ContactOptions& options);

}  // namespace tonus::indep
