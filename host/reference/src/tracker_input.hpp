// A tracker's sample turned into its bone's pose, with the rules for bad and
// missing samples: a non-finite or non-rotation sample is ignored; a lost
// tracker is held, then eased to a neutral pose; a returning one is blended
// back in.
#pragma once

#include "tonus/host/reference/tracker_ik.hpp"

namespace tonus::reference::detail {

// True when the sample can be used (finite, a rotation, not absurdly far).
bool usable_sample(const TrackerPose& p);

// Reads this frame's sample of one tracker into its track (the bone's pose
// through the calibration offset). Returns false when the sample was present
// but unusable.
bool read_sample(const TrackerPose& sample, const TrackerPose& offset, double dt_s, const IkOptions& options,
                 IkState::Track& track);

// The pose to use this frame, given the tracker's neutral (what the body
// would do without it); records it as shown and says how it was used.
TrackerPose effective_pose(const TrackerPose& neutral, double dt_s, const IkOptions& options, IkState::Track& track,
                           TrackerUse& use);

// Pose interpolation: position linear, rotation slerp.
TrackerPose blend(const TrackerPose& a, const TrackerPose& b, double w);

}  // namespace tonus::reference::detail
