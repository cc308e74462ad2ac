// Joint ranges outside the step: the swing-twist decomposition the limit rows
// use, and the clamp that puts a configuration inside every joint's range (a
// reference that asks for more than a joint can do would otherwise make a
// stiff drive press against the limit with an unbounded torque).
#pragma once

#include <span>

#include "tonus/sim/model.hpp"

namespace tonus::sim {

// q = swing * twist, the twist about the body-frame axis t. swing_rad is the
// angle between t and q t, swing_axis is unit (parent-rest frame, zero when
// there is no swing), twist_rad in (-pi, pi].
struct SwingTwist {
  double swing_rad = 0.0;
  Vec3 swing_axis = Vec3::Zero();
  double twist_rad = 0.0;
};
SwingTwist swing_twist(const Quat& q, const Vec3& t);

// One joint onto its range (nothing when the limit is disabled or the value
// is not finite). A ball joint's swing goes into the cone about the twist
// axis, keeping its direction, and its twist into [lower, upper]. True when
// it had to move.
bool clamp_ball(const JointLimit& limit, Quat& q);
bool clamp_hinge(const JointLimit& limit, double& angle_rad);

// Moves every limited joint of `qpos` (the model's layout) onto its range:
// hinge angles into [lower, upper]; ball joints' swing into the cone and their
// twist into [lower, upper], keeping the swing's direction. Returns how many
// joints were moved. Non-finite entries are left for the caller to reject.
int clamp_to_limits(const Model& model, std::span<double> qpos);

}  // namespace tonus::sim
