#include "tonus/host/reference/calibration.hpp"

#include <cmath>
#include <numbers>

#include "body_frames.hpp"
#include "tracker_input.hpp"

namespace tonus::reference {
namespace {

using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr double kHandLengthPerStature = 0.108;  // wrist to fingertip (Winter), as sim's humanoid
constexpr double kMinArmScale = 0.7;
constexpr double kMaxArmScale = 1.4;

std::size_t bi(Bone b) { return sim::index(b); }

}  // namespace

std::array<Vec3, sim::kBoneCount> calibrated_skeleton(const BodyCalibration& body) {
  auto o = sim::default_skeleton(body.height_m);
  for (const Bone b : {Bone::LeftLowerArm, Bone::LeftHand, Bone::RightLowerArm, Bone::RightHand}) {
    o[bi(b)] *= body.arm_scale;
  }
  return o;
}

sim::HumanoidSpec calibrated_spec(const BodyCalibration& body, double mass_kg) {
  sim::HumanoidSpec spec;
  spec.height_m = body.height_m;
  spec.mass_kg = mass_kg;
  spec.bone_offsets = calibrated_skeleton(body);
  return spec;
}

CalibrationResult calibrate(const TrackerFrame& standing, const CalibrationOptions& opt) {
  CalibrationResult r;
  for (const Tracker t : {Tracker::head, Tracker::left_hand, Tracker::right_hand}) {
    if (!detail::usable_sample(standing[t])) {
      r.error =
          "calibration needs the " + std::string(tracker_name(t)) + " tracker: its sample is missing or not finite";
      return r;
    }
  }
  BodyCalibration& body = r.body;
  const Vec3 hands = standing[Tracker::left_hand].pos_m - standing[Tracker::right_hand].pos_m;
  const Vec3 left = detail::horizontal(hands);
  if (left.norm() < 0.3) {
    r.error = "calibration: the hands are " + std::to_string(left.norm()) +
              " m apart sideways; stand with the arms out (T-pose) or down at the sides (A-pose)";
    return r;
  }
  const Vec3 forward = left.normalized().cross(Vec3::UnitZ());
  body.yaw_rad = std::atan2(forward.y(), forward.x());

  body.height_m = (standing[Tracker::head].pos_m.z() - opt.hmd_above_eyes_m) / opt.eye_height_per_stature;
  if (!(body.height_m >= opt.min_height_m && body.height_m <= opt.max_height_m)) {
    r.error = "calibration: the headset puts the stature at " + std::to_string(body.height_m) + " m, outside [" +
              std::to_string(opt.min_height_m) + ", " + std::to_string(opt.max_height_m) +
              "] m; is the floor at z = 0 and the performer standing?";
    return r;
  }

  // The body stands centred between the hands, feet on the floor.
  const auto rest = sim::default_skeleton(body.height_m);
  const Quat yaw = detail::yaw_quat(body.yaw_rad);
  const Vec3 mid = 0.5 * (standing[Tracker::left_hand].pos_m + standing[Tracker::right_hand].pos_m);
  const Vec3 root(mid.x(), mid.y(), rest[0].z());
  const Vec3 chest = root + yaw * (rest[bi(Bone::Spine)] + rest[bi(Bone::Chest)]);
  const double grip = opt.grip_beyond_wrist_per_stature * body.height_m;
  double scale_sum = 0.0, angle_sum = 0.0;
  std::array<Vec3, 2> arm_dir{};
  for (int s = 0; s < 2; ++s) {
    const Bone clavicle = s == 0 ? Bone::LeftShoulder : Bone::RightShoulder;
    const Tracker hand = s == 0 ? Tracker::left_hand : Tracker::right_hand;
    const Vec3 shoulder = chest + yaw * (rest[bi(clavicle)] + rest[bi(clavicle) + 1]);
    const Vec3 to_hand = standing[hand].pos_m - shoulder;
    const double default_arm = rest[bi(clavicle) + 2].norm() + rest[bi(clavicle) + 3].norm();
    scale_sum += (to_hand.norm() - grip) / default_arm;
    angle_sum += std::asin(std::clamp(-to_hand.z() / std::max(to_hand.norm(), 1e-9), -1.0, 1.0));
    arm_dir[static_cast<std::size_t>(s)] = yaw.conjugate() * to_hand.normalized();
  }
  body.arm_scale = 0.5 * scale_sum;
  body.arm_angle_rad = 0.5 * angle_sum;
  if (!(body.arm_scale >= kMinArmScale && body.arm_scale <= kMaxArmScale)) {
    r.error = "calibration: the hands put the arms at " + std::to_string(body.arm_scale) +
              " of a typical length for the stature; hold the controllers with the arms straight";
    return r;
  }
  const auto o = calibrated_skeleton(body);
  const double arm_m = o[bi(Bone::LeftLowerArm)].norm() + o[bi(Bone::LeftHand)].norm();
  body.arm_span_m = 2.0 * (std::abs(o[bi(Bone::LeftShoulder)].y()) + o[bi(Bone::LeftUpperArm)].norm() + arm_m +
                           kHandLengthPerStature * body.height_m);

  // The calibration pose: upright at the heading, the arms straight toward the controllers.
  detail::BodyFrames f;
  f.rot.fill(yaw);
  for (int s = 0; s < 2; ++s) {
    const Bone upper = s == 0 ? Bone::LeftUpperArm : Bone::RightUpperArm;
    const Vec3 rest_dir = o[bi(upper) + 1].normalized();
    const Quat arm = (yaw * sim::quat_from_two_vectors(rest_dir, arm_dir[static_cast<std::size_t>(s)])).normalized();
    for (std::size_t k = 0; k < 3; ++k) f.rot[bi(upper) + k] = arm;
  }
  detail::place_bones(o, root, f);
  for (std::size_t t = 0; t < kTrackerCount; ++t) {
    if (!detail::usable_sample(standing.pose[t])) continue;
    const std::size_t b = bi(tracked_bone(static_cast<Tracker>(t)));
    const TrackerPose bone{f.pos[b], f.rot[b], true};
    TrackerPose sample = standing.pose[t];
    sample.rot.normalize();
    body.offset[t] = compose(inverse(bone), sample);
  }
  return r;
}

}  // namespace tonus::reference
