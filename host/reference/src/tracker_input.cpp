#include "tracker_input.hpp"

#include <algorithm>
#include <cmath>

#include "smoothstep.hpp"

namespace tonus::reference::detail {
namespace {

constexpr double kFarthest_m = 1e3;  // a tracking space is never this large

}  // namespace

bool usable_sample(const TrackerPose& p) {
  return p.valid && p.pos_m.allFinite() && p.rot.coeffs().allFinite() && std::abs(p.rot.norm() - 1.0) < 0.1 &&
         p.pos_m.norm() < kFarthest_m;
}

TrackerPose blend(const TrackerPose& a, const TrackerPose& b, double w) {
  return {a.pos_m + w * (b.pos_m - a.pos_m), a.rot.slerp(w, b.rot).normalized(), true};
}

bool read_sample(const TrackerPose& sample, const TrackerPose& offset, double dt_s, const IkOptions& options,
                 IkState::Track& track) {
  const bool usable = usable_sample(sample);
  if (usable) {
    TrackerPose s = sample;
    s.rot.normalize();
    if (options.input_filter) {
      // A sample after a loss starts the filter afresh (dt 0): no smoothing across the gap.
      s = one_euro(s, track.lost_s > 0.0 ? 0.0 : dt_s, options.filter, track.filter);
    }
    if (track.seen && track.lost_s > 0.0) track.recover_left_s = options.recover_s;
    track.target = compose(s, inverse(offset));
    track.target.valid = true;
    track.lost_s = 0.0;
    track.seen = true;
  } else {
    track.target.valid = false;
    if (track.seen && track.lost_s == 0.0) track.held = track.shown.valid ? track.shown : track.target;
    if (track.seen) track.lost_s += dt_s;
  }
  return usable || !sample.valid;
}

TrackerPose effective_pose(const TrackerPose& neutral, double dt_s, const IkOptions& options, IkState::Track& track,
                           TrackerUse& use) {
  TrackerPose pose;
  if (!track.seen) {
    use = TrackerUse::neutral;
    pose = neutral;
  } else if (track.target.valid) {
    const TrackerPose live = track.target;
    if (track.recover_left_s > 0.0 && track.shown.valid) {
      // Close the gap left by the loss over the recovery time, evenly.
      const double w = std::clamp(dt_s / track.recover_left_s, 0.0, 1.0);
      pose = blend(track.shown, live, w);
      track.recover_left_s = std::max(0.0, track.recover_left_s - dt_s);
      use = TrackerUse::recovering;
    } else {
      track.recover_left_s = 0.0;
      pose = live;
      use = TrackerUse::live;
    }
  } else {
    // Held at the last valid pose, then eased toward the neutral one.
    const TrackerPose held = track.held.valid ? track.held : neutral;
    if (track.lost_s <= options.hold_s) {
      use = TrackerUse::held;
      pose = held;
    } else {
      const double w = smoothstep((track.lost_s - options.hold_s) / std::max(options.ease_s, 1e-9));
      use = w >= 1.0 ? TrackerUse::neutral : TrackerUse::easing;
      pose = blend(held, neutral, w);
    }
  }
  pose.valid = true;
  track.shown = pose;
  return pose;
}

}  // namespace tonus::reference::detail
