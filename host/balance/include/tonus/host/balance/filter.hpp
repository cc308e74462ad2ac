// The ZMP balance filter: where the ZMP of a motion leaves the support
// polygon, the target is the polygon's nearest point (kept a margin inside),
// and the waist (root) rotation is corrected until the ZMP reaches it, while
// the lower body keeps its captured world pose: the feet do not move, and
// the thighs and shanks follow the pelvis with a two-bone IK that keeps each
// knee in its captured plane. The waist turns about the midpoint of the hip
// joints: pitching it moves neither hip joint, while rolling it lifts one hip
// and lowers the other, which a straight stance leg cannot follow; the filter
// penalises such over-reach, so it corrects by pitch and yaw where it must.
//
// The corrections (a rotation vector per frame, about the root joint, in the
// world) are solved together by Gauss-Newton: the residuals are the ZMP's
// distance to its target, the correction's angular acceleration and its size,
// and the Jacobian couples neighbouring frames through the accelerations the
// corrections cause. Residuals are always evaluated exactly (the analysis'
// own smoothing and differentiation on the corrected motion); the Jacobian
// models the accelerations by a second difference. Frames whose ZMP cannot be
// brought in within the correction limit, or whose legs cannot reach their
// feet, are flagged as unsolved, never silently left.
#pragma once

#include <string>
#include <vector>

#include "tonus/host/balance/analysis.hpp"

namespace tonus::balance {

struct FilterOptions {
  AnalysisOptions analysis;
  double margin_m = 0.01;           // targets this far inside the polygon
  double max_correction_rad = 0.6;  // per frame; beyond it a frame is unsolved
  double smoothness = 0.1;          // weight of the correction's angular acceleration (ZMP-equivalent metres)
  double size_weight = 0.05;        // weight of the correction's size (ZMP-equivalent metres)
  int max_iterations = 40;
};

struct FilterResult {
  HumanMotion corrected;
  std::vector<Vec3> correction;  // per frame: the waist rotation (rotation vector, world, rad)
  Analysis before;
  Analysis after;
  std::vector<bool> unsolved;  // per frame
  std::size_t frames_unsolved = 0;
  double max_foot_displacement_m = 0.0;  // of the feet's landmarks (zero up to rounding unless a leg could not reach)
  int iterations = 0;
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Progress callback: (iteration, frames still outside); may be empty.
using FilterProgress = void (*)(int iteration, std::size_t frames_outside, void* user);

FilterResult balance_filter(const HumanMotion& motion, const FilterOptions& options, FilterProgress progress = nullptr,
                            void* user = nullptr);

// One frame with the waist rotated by `delta` about the midpoint of the hip
// joints, the pelvis and upper body following rigidly and the legs re-solved
// to keep the feet. `reachable` is false when a leg had to stretch beyond its
// length; `overreach_m` (two values, left and right), when given, receives how
// far each hip-to-ankle distance exceeds 99.9 % of the leg's length (negative: slack).
MotionFrame rotate_waist(const MotionFrame& frame, const Vec3& delta, bool& reachable, double* overreach_m = nullptr);

}  // namespace tonus::balance
