// From a BVH clip to the balance analysis' HumanMotion: forward kinematics,
// the file's Y-up frame turned into the internal Z-up frame (x_int = z_bvh,
// y_int = x_bvh, z_int = y_bvh, a proper rotation), lengths in metres, the
// extremities a skeleton lacks synthesised from body proportions, and a
// leading T-pose frame detected and excluded.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "tonus/host/balance/landmarks.hpp"
#include "tonus/host/balance/skeleton_map.hpp"
#include "tonus/host/motion/clip.hpp"
#include "tonus/host/motion/kinematics.hpp"

namespace tonus::balance {

struct ConvertOptions {
  std::optional<double> metres_per_unit;  // absent: guessed from the leg length
  bool exclude_tpose = true;
};

// What stays the same over a clip: the mapping, the scale, and the sizes used
// to synthesise missing extremities. Made by convert_motion, reused by the
// balance filter to turn corrected clips back into landmarks.
struct SkeletonGeometry {
  SkeletonMap map;
  double metres_per_unit = 1.0;
  int head_top_joint = -1;           // an End Site above the head, when the file has a real one
  int hand_far_joint[2] = {-1, -1};  // the farthest point below each hand (fingertip)
  int toe_tip_joint[2] = {-1, -1};   // the toes' End Site, when real
  double thigh_m = 0.0, shank_m = 0.0, forearm_m = 0.0, foot_m = 0.0;
};

struct Conversion {
  HumanMotion motion;
  SkeletonGeometry geometry;
  std::string unit_name;  // "m", "cm", "mm", "inch", "CMU unit (0.056444 m)" or "given"
  bool unit_guessed = false;
  bool tpose_excluded = false;
  std::vector<std::string> messages;  // human-readable notes: unit guess, T-pose, synthesised bones
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

Conversion convert_motion(const motion::Clip& clip, const MapResult& mapping, const ConvertOptions& options);

// One frame's landmarks and bone rotations from its poses (file frame).
void landmarks_from_poses(const SkeletonGeometry& g, const std::vector<motion::JointPose>& poses, MotionFrame& out);

// A streamed skeleton's geometry (no BVH file: joint positions only, no End
// Sites): the thigh, shank and forearm lengths (m) from which landmarks_from_bones
// synthesises the extremities, as convert_motion does for a file without them.
SkeletonGeometry geometry_from_lengths(double thigh_m, double shank_m, double forearm_m);

// One frame's landmarks from its bones: `frame` holds the joint position and
// world rotation (internal frame, metres) of each bone `have` names; the rest
// (missing spine joints, shoulders, neck or head, head top, hand and toe tips,
// heels, mid-hip) are synthesised as for a BVH frame. `g`'s End Sites are not used.
void landmarks_from_bones(const SkeletonGeometry& g, const std::array<bool, sim::kBoneCount>& have, MotionFrame& frame);

// The fixed change of axes between the file (Y up) and the internal frame (Z up).
Quat file_to_internal();

}  // namespace tonus::balance
