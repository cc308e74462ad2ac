// The joints the estimator needs, found by name in a BVH skeleton, and their
// world positions in the internal frame (right-handed, Z up, metres).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tonus/host/motion/clip.hpp"

namespace tonus::indep {

using Vec3 = Eigen::Vector3d;

// Joint centres. The trunk is de Leva's single cervicale-to-mid-hip segment,
// so no spine joint is needed; the neck joint stands for the cervicale (C7).
enum Site : std::size_t {
  neck,
  head,
  left_hip,
  left_knee,
  left_ankle,
  left_toe,
  left_shoulder,
  left_elbow,
  left_wrist,
  right_hip,
  right_knee,
  right_ankle,
  right_toe,
  right_shoulder,
  right_elbow,
  right_wrist,
  kSiteCount
};
// Right-side site = left-side site + kRightOffset.
inline constexpr std::size_t kRightOffset = right_hip - left_hip;

using Sites = std::array<Vec3, kSiteCount>;

// Clip joint index of every site; error names the sites not found.
struct SkeletonMap {
  std::array<std::size_t, kSiteCount> joint{};
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Matches joint names (End Sites excluded), ignoring case, against two
// conventions: CMU as converted by cgspeed (LeftUpLeg, LeftLeg, LeftFoot,
// LeftToeBase, LeftArm, LeftForeArm, LeftHand, Neck, Head) and Bandai Namco's
// (UpperLeg_L, LowerLeg_L, Foot_L, Toes_L, UpperArm_L, LowerArm_L, Hand_L).
[[nodiscard]] SkeletonMap map_skeleton(const motion::Clip& clip);

// BVH is Y up; internal = (x, -z, y) of the file's (x, y, z) (a rotation of
// +90 degrees about x, so still right-handed), times metres_per_unit.
[[nodiscard]] Vec3 to_internal(const Eigen::Vector3d& file, double metres_per_unit);

// The sites of frames [first_frame, frame_count), one entry per frame.
// Empty if forward kinematics fails on a frame.
[[nodiscard]] std::vector<Sites> site_positions(const motion::Clip& clip, const SkeletonMap& map,
                                                double metres_per_unit, std::size_t first_frame);

}  // namespace tonus::indep
