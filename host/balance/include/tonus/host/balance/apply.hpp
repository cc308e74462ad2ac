// Writes the balance filter's waist corrections back into a BVH clip: the
// hips joint's rotation and position channels (the waist turns about the
// midpoint of the hip joints), and the thigh, shank and foot rotations that
// keep each foot where it was. Each joint keeps its own channel order and its
// angles stay continuous: every joint written is re-expressed, from its first
// written frame on, as the angles nearest the previous frame's (no rotation
// changes), so the file gains no Euler jump and loses those the original had
// in these joints. The result is measured, not assumed: the feet's
// displacement and the joint-angle changes come from forward kinematics of
// the written clip against the original.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/filter.hpp"

namespace tonus::balance {

// A joint's local rotation changed by more than this (radians) at a frame
// counts as changed there.
inline constexpr double kChangedRad = 1e-6;

// The largest change of one joint's local rotation over the clip.
struct JointChange {
  std::string joint;      // the BVH joint's name
  std::string bone;       // its HumanBodyBones name; empty if unmapped
  double max_rad = 0.0;   // angle between the original and the written local rotation
  std::size_t frame = 0;  // where it occurs (0-based)
};

struct AppliedCorrection {
  motion::Clip clip;
  double max_foot_displacement_m = 0.0;        // ankles, toe joints and toe tips, over every frame it is planted
  double max_swing_foot_displacement_m = 0.0;  // the same where a swinging foot followed the pelvis
  // The local-rotation change over the (joint, frame) samples that changed
  // (by more than kChangedRad), every joint and frame considered: the size of
  // the edit where it was made.
  double rms_change_changed_joints_rad = 0.0;
  std::size_t changed_samples = 0;
  std::vector<JointChange> largest_change;  // every joint that changed, in file order
  // The older figure: every mapped joint over analysed frames, untouched
  // ones included, so it understates the edit (1.7 to 2.4 times on the
  // shared clips).
  double rms_change_all_mapped_joints_rad = 0.0;
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// `motion` is the clip's conversion (convert_motion) and `correction` the
// filter's, one rotation vector per frame (internal frame, radians),
// `shift_m` the pelvis's horizontal shift per frame (internal frame, metres;
// empty: none) and `follow` how much each swinging foot follows the pelvis
// per frame (WaistTurn::follow; empty: the feet stay), and `drop_m` how far the
// pelvis is lowered at least per frame (the filter's drop, smoothed over time;
// empty: as far as each frame's legs need), and `arm_swing_rad` each arm's swing
// per frame (left, right; arm_swing.hpp; empty: the arms keep their rotations).
AppliedCorrection apply_correction(const motion::Clip& clip, const SkeletonGeometry& geometry,
                                   const HumanMotion& motion, const std::vector<Vec3>& correction,
                                   const std::vector<Vec2>& shift_m = {},
                                   const std::vector<std::array<double, 2>>& follow = {},
                                   const std::vector<double>& drop_m = {}, const std::vector<Vec2>& arm_swing_rad = {});

}  // namespace tonus::balance
