// The 1-euro filter (Casiez, Roussel and Vogel, CHI 2012) on a tracker's pose:
// a first-order low-pass whose cutoff rises with the speed, so a still
// tracker's noise is smoothed hard and a fast one lags little. Position and
// rotation each adapt to their own speed.
#pragma once

#include "tonus/host/reference/trackers.hpp"

namespace tonus::reference {

struct OneEuroParams {
  double min_cutoff_hz = 1.0;
  double position_beta = 2.0;  // cutoff added per m/s
  double rotation_beta = 0.5;  // cutoff added per rad/s
  double derivative_cutoff_hz = 1.0;
};

struct OneEuroState {
  bool started = false;
  sim::Vec3 pos = sim::Vec3::Zero();
  sim::Quat rot = sim::Quat::Identity();
  sim::Vec3 velocity = sim::Vec3::Zero();          // smoothed, m/s
  sim::Vec3 angular_velocity = sim::Vec3::Zero();  // smoothed, rad/s (world)
};

// Filters one valid sample taken dt_s after the previous; dt_s <= 0 passes it
// through unchanged (and restarts from it).
TrackerPose one_euro(const TrackerPose& sample, double dt_s, const OneEuroParams& params, OneEuroState& state);

}  // namespace tonus::reference
