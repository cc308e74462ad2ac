// Tracked points a VR performer wears: a headset and two controllers (3-point
// tracking), optionally a waist and two foot trackers (6-point), and optional
// elbow and knee trackers that only say where a joint points. Poses are in the
// internal frame (right-handed, Z up, metres, floor at z = 0); conversion from
// an engine's frame happens where the data comes in.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::reference {

enum class Tracker : std::uint8_t {
  head,
  left_hand,
  right_hand,
  waist,
  left_foot,
  right_foot,
  left_elbow,
  right_elbow,
  left_knee,
  right_knee,
};
inline constexpr std::size_t kTrackerCount = 10;

constexpr std::size_t index(Tracker t) { return static_cast<std::size_t>(t); }

// The bone a tracker is strapped to.
constexpr sim::Bone tracked_bone(Tracker t) {
  switch (t) {
    case Tracker::head: return sim::Bone::Head;
    case Tracker::left_hand: return sim::Bone::LeftHand;
    case Tracker::right_hand: return sim::Bone::RightHand;
    case Tracker::waist: return sim::Bone::Hips;
    case Tracker::left_foot: return sim::Bone::LeftFoot;
    case Tracker::right_foot: return sim::Bone::RightFoot;
    case Tracker::left_elbow: return sim::Bone::LeftLowerArm;
    case Tracker::right_elbow: return sim::Bone::RightLowerArm;
    case Tracker::left_knee: return sim::Bone::LeftLowerLeg;
    case Tracker::right_knee: return sim::Bone::RightLowerLeg;
  }
  return sim::Bone::Hips;
}

constexpr std::string_view tracker_name(Tracker t) {
  switch (t) {
    case Tracker::head: return "head";
    case Tracker::left_hand: return "left_hand";
    case Tracker::right_hand: return "right_hand";
    case Tracker::waist: return "waist";
    case Tracker::left_foot: return "left_foot";
    case Tracker::right_foot: return "right_foot";
    case Tracker::left_elbow: return "left_elbow";
    case Tracker::right_elbow: return "right_elbow";
    case Tracker::left_knee: return "left_knee";
    case Tracker::right_knee: return "right_knee";
  }
  return "?";
}

// A rigid pose, world from local. `valid` false: no sample (never seen, or
// dropped this frame).
struct TrackerPose {
  sim::Vec3 pos_m = sim::Vec3::Zero();
  sim::Quat rot = sim::Quat::Identity();
  bool valid = false;
};

// One sample of every tracker at one time.
struct TrackerFrame {
  double time_s = 0.0;
  std::array<TrackerPose, kTrackerCount> pose{};

  TrackerPose& operator[](Tracker t) { return pose[index(t)]; }
  const TrackerPose& operator[](Tracker t) const { return pose[index(t)]; }
};

// a * b as rigid transforms (world from a's local, then a's local from b's).
inline TrackerPose compose(const TrackerPose& a, const TrackerPose& b) {
  return {a.pos_m + a.rot * b.pos_m, (a.rot * b.rot).normalized(), a.valid && b.valid};
}

inline TrackerPose inverse(const TrackerPose& a) {
  const sim::Quat r = a.rot.conjugate();
  return {-(r * a.pos_m), r, a.valid};
}

}  // namespace tonus::reference
