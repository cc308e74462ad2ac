// Calibration from a standing sample, as VR body-tracking apps do it: the
// performer stands upright, facing forward, arms out (T-pose) or down at an
// angle (A-pose), and one sample of every tracker gives their height, their
// arm length and span, and each tracker's offset to its bone.
//
// Assumptions (each an option): the floor is z = 0; the headset's tracked
// point is at the eyes, and eye height is 0.936 of stature (Drillis & Contini
// 1966); a controller's tracked point lies on the line of the forearm, a fixed
// fraction of the height beyond the wrist; the feet stand flat under the
// shoulders, pointing forward; the hands are level with the forearms. The
// heading is taken from the line between the hands, so a tracker's own axes
// need no convention.
#pragma once

#include <array>
#include <string>

#include "tonus/host/reference/trackers.hpp"
#include "tonus/sim/humanoid.hpp"

namespace tonus::reference {

struct CalibrationOptions {
  double eye_height_per_stature = 0.936;
  double hmd_above_eyes_m = 0.0;                 // where the headset's tracked point sits above the eyes
  double grip_beyond_wrist_per_stature = 0.043;  // controller point to wrist, along the forearm (0.4 of a hand)
  double min_height_m = 1.0;                     // a standing sample outside this range is refused
  double max_height_m = 2.4;
};

struct BodyCalibration {
  double height_m = 1.70;      // stature
  double arm_scale = 1.0;      // upper arm and forearm length / the default skeleton's at this height
  double arm_span_m = 1.70;    // fingertip to fingertip, arms out
  double arm_angle_rad = 0.0;  // the arms' angle below horizontal in the sample (T-pose about 0, A-pose 0.5-0.8)
  double yaw_rad = 0.0;        // the heading the performer faced (0: +X)
  // Each tracker's pose in its bone's frame (tracked_bone), for the trackers
  // the sample had.
  std::array<TrackerPose, kTrackerCount> offset{};
};

struct CalibrationResult {
  BodyCalibration body;
  std::string error;  // non-empty: the sample was refused (no calibration made)
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Needs the head and both hands; uses any other tracker the sample has.
CalibrationResult calibrate(const TrackerFrame& standing, const CalibrationOptions& options = {});

// The default skeleton at the calibrated height with the arms scaled to the
// measured length (sim::default_skeleton's layout).
std::array<sim::Vec3, sim::kBoneCount> calibrated_skeleton(const BodyCalibration& body);

// A humanoid spec for the performer (build it with sim::build_humanoid).
sim::HumanoidSpec calibrated_spec(const BodyCalibration& body, double mass_kg);

}  // namespace tonus::reference
