#include "tonus/host/balance/arm_swing.hpp"

#include <Eigen/Geometry>

namespace tonus::balance {
namespace {

using sim::Bone;

struct Arm {
  Bone upper, lower, hand;
  Landmark tip;
};
constexpr Arm kArms[2] = {{Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand, Landmark::LeftHandTip},
                          {Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand, Landmark::RightHandTip}};

}  // namespace

Quat arm_swing_turn(const Vec3& left_shoulder, const Vec3& right_shoulder, double swing_rad) {
  // Toward the right shoulder: a positive turn about it takes a hanging arm
  // forward (right-handed, Z up).
  Vec3 axis = right_shoulder - left_shoulder;
  axis.z() = 0.0;
  if (swing_rad == 0.0 || axis.norm() < 1e-9) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(swing_rad, axis.normalized()));
}

MotionFrame swing_arms(const MotionFrame& frame, const Vec2& swing_rad) {
  MotionFrame out = frame;
  const Vec3 left = frame.p[sim::index(Bone::LeftUpperArm)], right = frame.p[sim::index(Bone::RightUpperArm)];
  for (std::size_t side = 0; side < 2; ++side) {
    const Arm& arm = kArms[side];
    const Quat turn = arm_swing_turn(left, right, swing_rad(static_cast<Eigen::Index>(side)));
    if (turn.vec().isZero(0.0)) continue;
    const Vec3 pivot = frame.p[sim::index(arm.upper)];
    for (const Bone b : {arm.lower, arm.hand}) out.p[sim::index(b)] = pivot + turn * (frame.p[sim::index(b)] - pivot);
    out.p[index(arm.tip)] = pivot + turn * (frame.p[index(arm.tip)] - pivot);
    for (const Bone b : {arm.upper, arm.lower, arm.hand})
      out.rotation[sim::index(b)] = turn * frame.rotation[sim::index(b)];
  }
  return out;
}

}  // namespace tonus::balance
