// The ZMP balance filter: where the ZMP of a motion leaves the support
// polygon, the target is the polygon's nearest point (kept a margin inside),
// and the waist (root) rotation is corrected until the ZMP reaches it, while
// the lower body keeps its captured world pose: the feet do not move, and
// the thighs and shanks follow the pelvis with a two-bone IK that keeps each
// knee in its captured plane. The waist turns about the midpoint of the hip
// joints: pitching it moves neither hip joint, while rolling it lifts one hip
// and lowers the other; where a straight stance leg could not follow, the
// pelvis is lowered by the millimetres it needs (the knee bends a little)
// instead of the foot moving.
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

#include <array>
#include <string>
#include <vector>

#include "tonus/host/balance/analysis.hpp"

namespace tonus::balance {

struct FilterOptions {
  AnalysisOptions analysis;
  double margin_m = 0.01;           // targets this far inside the polygon
  double max_correction_rad = 1.0;  // per frame; a frame that needs more is unsolved
  double smoothness = 0.1;          // weight of the correction's angular acceleration (ZMP-equivalent metres)
  double size_weight = 0.05;        // weight of the correction's size (ZMP-equivalent metres)
  int max_iterations = 100;
};

struct FilterResult {
  HumanMotion corrected;
  std::vector<Vec3> correction;               // per frame: the waist rotation (rotation vector, world, rad)
  std::vector<Vec2> shift_m;                  // per frame: the pelvis's horizontal shift (world, m); empty: none
  std::vector<std::array<double, 2>> follow;  // per frame and leg: a swinging foot's share (empty: none)
  Analysis before;
  Analysis after;
  std::vector<bool> unsolved;  // per frame
  std::size_t frames_unsolved = 0;
  double max_foot_displacement_m = 0.0;  // of the feet's landmarks (zero up to rounding)
  double max_drop_m = 0.0;               // the largest vertical pelvis shift the legs needed
  std::vector<double> drop_m;            // per frame: the pelvis lowered at least this much (empty: as needed)
  std::vector<Vec2> arm_swing_rad;       // per frame: each arm's swing (arm_swing.hpp; empty: none)
  double max_arm_swing_rad = 0.0;
  int iterations = 0;
  std::size_t operator_band = 0;  // frames on each side a frame's acceleration depends on (the look-ahead)
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Progress callback: (iteration, frames still outside); may be empty.
using FilterProgress = void (*)(int iteration, std::size_t frames_outside, void* user);

FilterResult balance_filter(const HumanMotion& motion, const FilterOptions& options, FilterProgress progress = nullptr,
                            void* user = nullptr);

// The waist correction of one frame: a turn by `delta` about the midpoint of
// the hip joints, then a vertical shift of the pelvis and everything above it
// (drop_m > 0: down) by the few millimetres a straight leg needs to keep
// reaching its foot. `reachable` is false when no shift lets both legs reach
// (a foot will move: the frame is flagged).
struct WaistTurn {
  Quat rotation = Quat::Identity();
  Vec3 pivot = Vec3::Zero();
  Vec3 shift = Vec3::Zero();  // horizontal, after the turn
  // Per leg (left, right): how much its foot follows the pelvis, 0 (planted:
  // the foot stays, the leg is re-solved) to 1 (swinging: the leg moves rigidly).
  std::array<double, 2> follow{};
  // Where that leg's ankle goes, and its foot's turn.
  [[nodiscard]] Vec3 ankle_target(const Vec3& ankle, std::size_t leg) const;
  [[nodiscard]] Quat foot_turn(std::size_t leg) const;
  // The unit direction, square to the re-solved leg's line from its moved hip
  // joint `hip` to its ankle `ankle`, that its knee bends toward: the side the
  // captured knee bends to from the captured line (carried with the foot's
  // share of the turn), pulled toward the toes by up to a few millimetres as
  // the hip moves (none with no correction, which then changes nothing) so a
  // straight captured leg bends forward. Measured from the moved hip instead,
  // the captured knee of a nearly straight leg lies behind the new line once
  // the hip has moved further than the knee's bend, and the knee flips.
  [[nodiscard]] Vec3 knee_side(const MotionFrame& frame, std::size_t leg, const Vec3& hip, const Vec3& ankle) const;

  double drop_m = 0.0;
  bool reachable = true;
};
// `shift_m` moves the pelvis and everything above it horizontally after the
// turn (the robust filter's pelvis translation; zero for this filter). The
// drop is the least the legs need, or `min_drop_m` where that is more and the
// legs allow it (a drop smoothed over time: drop_envelope.hpp).
WaistTurn waist_turn(const MotionFrame& frame, const Vec3& delta, const Vec2& shift_m = Vec2::Zero(),
                     const std::array<double, 2>& follow = {}, double min_drop_m = 0.0);

// The frame with that correction applied: pelvis and upper body moved
// rigidly, both legs re-solved by two-bone IK to keep their feet.
MotionFrame rotate_waist(const MotionFrame& frame, const Vec3& delta, double* drop_m = nullptr,
                         bool* reachable = nullptr);
// How far a hip joint may be from its ankle for the waist correction's
// two-bone IK: 99.9 % of the leg (a sliver of knee bend rather than a singular
// straight leg), or as far as the capture already has it (a kick's straight leg).
double leg_reach_m(const Vec3& hip, const Vec3& knee, const Vec3& ankle);

// The same with a horizontal pelvis shift after the turn.
MotionFrame correct_waist(const MotionFrame& frame, const Vec3& delta, const Vec2& shift_m, double* drop_m = nullptr,
                          bool* reachable = nullptr, const std::array<double, 2>& follow = {}, double min_drop_m = 0.0);

}  // namespace tonus::balance
