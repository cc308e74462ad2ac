// One clip frame to one humanoid configuration by direction matching: each
// bone is turned so its rest direction points along the clip's segment, its
// twist set by an anatomical reference, elbows and knees fitted to the limb's
// plane, every joint clamped into its range.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "rig.hpp"
#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/balance/landmarks.hpp"

namespace tonus::reference::detail {

// Twist references measured over the whole clip, each a constant axis in the
// frame of one clip bone (its BVH rotation), so a clip's own joint
// conventions need no table. Absent when the clip gives no consistent axis.
struct Calibration {
  std::array<std::optional<Vec3>, 2> elbow_axis;  // [left, right], in the upper arm's clip frame
  std::array<std::optional<Vec3>, 2> knee_axis;   // in the thigh's clip frame
  std::array<std::optional<Vec3>, 2> hand_axis;   // the elbow axis, in the hand's clip frame
  std::array<std::optional<Vec3>, 2> hand_dir;    // wrist to hand tip, in the hand's clip frame
  std::array<std::optional<Vec3>, 2> foot_left;   // the foot's horizontal left while it stands, in its clip frame
  std::optional<Vec3> head_left;                  // the shoulder line, in the head's clip frame
  std::array<std::optional<double>, 2> flat_foot_pitch_rad;  // the clip's ankle-to-ball line below level, foot flat
};

Calibration calibrate(const balance::HumanMotion& motion, const balance::ContactTrack& contacts);

// What makes the humanoid's neutral the clip's, where skeletons differ.
// Trunk and shoulders (CMU's shoulders start at the spine, its pelvis tilts):
// when a clip starts with a T-pose, each keeps, in its own frame, the offset
// that makes it rest there. Feet and toes: where the clip's foot stands flat,
// the humanoid's does (its ankle-to-ball line and toe geometry differ from
// every skeleton's). Limbs and hands are matched as they are.
struct Neutral {
  std::array<Quat, sim::kBoneCount> offset;  // right of the matched rotation (Hips, Shoulders)
  std::array<double, 2> foot_pitch_rad{};    // the feet turned toe-up by this about their left axis
  std::array<double, 2> toe_rad{};           // subtracted from the toes' matched angle
  Neutral() { offset.fill(Quat::Identity()); }
};

struct FrameResult {
  std::array<double, sim::kMaxQpos> qpos{};
  std::array<bool, sim::kBoneCount> clamped{};  // joints moved into their limits
  std::array<double, 2> toe_matched_rad{};      // the toes' angle before the neutral and the clamp
};

// `root_target`: where the midpoint of the humanoid's hip joints goes. With
// `measure`, the frame is a T-pose: the root is put upright and the shoulders
// at rest, and the offsets that does are written there.
void solve_frame(const Rig& rig, const Calibration& cal, const Neutral& neutral, const balance::MotionFrame& frame,
                 const Vec3& root_target, FrameResult& out, Neutral* measure = nullptr);

// The neutral of a clip (see Neutral); notes what it found.
Neutral measure_neutral(const Rig& rig, const Calibration& cal, const balance::HumanMotion& motion,
                        const balance::ContactTrack& contacts, std::vector<std::string>& notes);

}  // namespace tonus::reference::detail
