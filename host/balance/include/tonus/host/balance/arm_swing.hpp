// The robust filter's arm swing (issue 14: more of the body than the waist).
// Each arm turns as a whole about the horizontal line through its shoulder
// joint (the upper arm's joint) that runs parallel to the line between the
// two shoulder joints, forward positive: the swing of a walking arm. It is
// applied after the waist correction, so the line is the corrected pose's.
// An arm carries about 5 % of the body's mass at 0.3 m from its shoulder, so
// a swing moves the centre of mass little but its acceleration moves the ZMP
// (a punch's recovery, a runner's arms), at the cost of the arm's path only.
#pragma once

#include "tonus/host/balance/landmarks.hpp"

namespace tonus::balance {

// The turn that swings an arm by `swing_rad`, from the two shoulder joints'
// positions (only their difference counts); identity where they are level
// above one another.
Quat arm_swing_turn(const Vec3& left_shoulder, const Vec3& right_shoulder, double swing_rad);

// The frame with each arm (left, right) swung: the elbow, wrist and hand's
// end turn about the shoulder joint, and so do the three bones' rotations.
MotionFrame swing_arms(const MotionFrame& frame, const Vec2& swing_rad);

}  // namespace tonus::balance
