// Two-bone limbs (upper arm + forearm, thigh + shank) solved in closed form:
// the law of cosines for the middle joint's angle, a pole direction for the
// plane the limb bends in.
#pragma once

#include "tonus/sim/math.hpp"

namespace tonus::reference::detail {

struct TwoBoneLimb {
  sim::Vec3 upper_dir;  // the upper bone's rest direction to the middle joint (its frame, unit)
  sim::Vec3 lower_dir;  // the lower bone's rest direction to the end joint (its frame, unit)
  sim::Vec3 hinge;      // the middle joint's axis (upper bone's frame, unit), positive angle = flexion
  double upper_m = 0.0;
  double lower_m = 0.0;
  // Soft reach: within this of full extension the limb straightens along an
  // exponential, never quite reaching straight (the end then falls short by
  // at most 0.37 of it). Near straight, the middle joint's position is the
  // square root of the slack, so without this any jitter in the target's
  // distance becomes a large jerk of the elbow or knee. 0: exact.
  double soft_m = 0.0;
};

struct TwoBoneSolution {
  sim::Quat upper = sim::Quat::Identity();  // the upper bone's world rotation
  double hinge_rad = 0.0;                   // the middle joint's angle
};

// The middle joint of two links of lengths a and b from `root`, whose end
// lies `dist` along the unit `dir` (dist within [|a - b|, a + b]): on the
// circle where the spheres about the root and the end meet, on the side of
// `pole` across the line (`fallback_pole` when that part vanishes). `side`
// is that unit direction across the line.
struct MiddleJoint {
  sim::Vec3 pos = sim::Vec3::Zero();
  sim::Vec3 side = sim::Vec3::Zero();
};
MiddleJoint place_middle_joint(const sim::Vec3& root, const sim::Vec3& dir, double dist, double a, double b,
                               const sim::Vec3& pole, const sim::Vec3& fallback_pole);

// Puts the end joint on `target` from the upper joint at `root`. The middle
// joint goes toward `pole` (the part of it across the root-target line);
// `fallback_pole` when that part vanishes. The positive hinge angle must bend
// the limb toward the side the pole names as the middle joint's.
TwoBoneSolution solve_two_bone(const TwoBoneLimb& limb, const sim::Vec3& root, const sim::Vec3& target,
                               const sim::Vec3& pole, const sim::Vec3& fallback_pole);

}  // namespace tonus::reference::detail
