// Writes the balance filter's waist corrections back into a BVH clip: the
// hips joint's rotation and position channels (the waist turns about the
// midpoint of the hip joints), and the thigh, shank and foot rotations that
// keep each foot where it was. Each joint keeps its own channel order and its
// angles stay continuous: every joint written is re-expressed, from its first
// written frame on, as the angles nearest the previous frame's (no rotation
// changes), so the file gains no Euler jump and loses those the original had
// in these joints. The result is measured, not assumed: the feet's
// displacement and the joint-angle change come from forward kinematics of the
// written clip against the original.
#pragma once

#include <string>
#include <vector>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/filter.hpp"

namespace tonus::balance {

struct AppliedCorrection {
  motion::Clip clip;
  double max_foot_displacement_m = 0.0;  // ankles, toe joints and toe tips, over every frame
  double rms_joint_change_rad = 0.0;     // local rotations of every mapped joint, over analysed frames
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// `motion` is the clip's conversion (convert_motion) and `correction` the
// filter's, one rotation vector per frame (internal frame, radians).
AppliedCorrection apply_correction(const motion::Clip& clip, const SkeletonGeometry& geometry,
                                   const HumanMotion& motion, const std::vector<Vec3>& correction);

}  // namespace tonus::balance
