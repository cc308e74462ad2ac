// A humanoid motion as the balance analysis sees it: per frame, the world
// positions (internal frame: right-handed, Z up, metres) of the joint centres
// of the HumanBodyBones bones plus the extremities the mass model and the
// feet need (head top, hand and toe tips, heels, the mid-hip point). Whatever
// a skeleton lacks is synthesised from its proportions when it is converted.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "tonus/sim/human_bones.hpp"

namespace tonus::balance {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

enum class Landmark : std::uint8_t {
  // 0 .. 20: the joint centre of each sim::Bone, in the same order.
  HeadTop = static_cast<std::uint8_t>(sim::kBoneCount),  // vertex
  LeftHandTip,                                           // third metacarpale region (end of the hand segment)
  RightHandTip,
  LeftToeTip,  // tip of the longest toe
  RightToeTip,
  LeftHeel,  // back of the heel, on the sole
  RightHeel,
  MidHip,  // midpoint of the hip joint centres
};

inline constexpr std::size_t kLandmarkCount = sim::kBoneCount + 8;

constexpr std::size_t index(Landmark l) { return static_cast<std::size_t>(l); }
constexpr Landmark joint_of(sim::Bone b) { return static_cast<Landmark>(sim::index(b)); }
std::string_view name(Landmark l);

using LandmarkFrame = std::array<Vec3, kLandmarkCount>;

// One frame: the landmarks and each bone's world rotation (from its frame in
// the skeleton's first frame, the reference the feet are measured in).
struct MotionFrame {
  LandmarkFrame p{};
  std::array<Quat, sim::kBoneCount> rotation{};
};

enum class Foot : std::uint8_t { left, right };

struct FootLandmarks {
  Landmark ankle, toe_joint, toe_tip, heel;
};
constexpr FootLandmarks foot_landmarks(Foot f) {
  return f == Foot::left ? FootLandmarks{joint_of(sim::Bone::LeftFoot), joint_of(sim::Bone::LeftToes),
                                         Landmark::LeftToeTip, Landmark::LeftHeel}
                         : FootLandmarks{joint_of(sim::Bone::RightFoot), joint_of(sim::Bone::RightToes),
                                         Landmark::RightToeTip, Landmark::RightHeel};
}

struct HumanMotion {
  double dt_s = 1.0 / 120.0;
  std::vector<MotionFrame> frames;
  std::size_t first_frame = 0;  // frames before it (a leading T-pose) are excluded from analysis
  [[nodiscard]] std::size_t size() const { return frames.size(); }
};

}  // namespace tonus::balance
