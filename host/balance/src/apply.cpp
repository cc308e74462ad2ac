#include "tonus/host/balance/apply.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "tonus/host/balance/arm_swing.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::balance {
namespace {

using sim::Bone;
using Vec3d = Eigen::Vector3d;
using Quatd = Eigen::Quaterniond;

// A joint's new local rotation from its parent's new global one and its own new global one.
Quatd local_from(const std::vector<motion::JointPose>& poses, const std::vector<Quatd>& global,
                 const motion::Clip& clip, std::size_t joint) {
  const int p = clip.joints[joint].parent;
  const Quatd parent = p >= 0 ? global[static_cast<std::size_t>(p)] : Quatd::Identity();
  (void)poses;
  return (parent.conjugate() * global[joint]).normalized();
}

}  // namespace

AppliedCorrection apply_correction(const motion::Clip& clip, const SkeletonGeometry& g, const HumanMotion& human,
                                   const std::vector<Vec3>& correction, const std::vector<Vec2>& shift_m,
                                   const std::vector<std::array<double, 2>>& follow, const std::vector<double>& drop_m,
                                   const std::vector<Vec2>& arm_swing_rad) {
  const std::size_t first_frame = human.first_frame;
  AppliedCorrection out;
  out.clip = clip;
  const auto bone = [&](Bone b) { return g.map.joint[sim::index(b)]; };
  const int hips = bone(Bone::Hips);
  const motion::Joint& hj = clip.joints[static_cast<std::size_t>(hips)];
  int position_channels = 0;
  for (const motion::Channel c : hj.channels) position_channels += motion::is_rotation(c) ? 0 : 1;
  if (position_channels != 3) {
    out.error = "the hips joint '" + hj.name + "' has no position channels: the waist cannot turn about the hip joints";
    return out;
  }
  if (correction.size() != clip.frame_count || human.size() != clip.frame_count ||
      (!shift_m.empty() && shift_m.size() != clip.frame_count) ||
      (!follow.empty() && follow.size() != clip.frame_count) ||
      (!drop_m.empty() && drop_m.size() != clip.frame_count) ||
      (!arm_swing_rad.empty() && arm_swing_rad.size() != clip.frame_count)) {
    out.error = "one correction per frame is needed";
    return out;
  }
  const Quatd to_int = file_to_internal();
  // The first frame each joint's rotation is written at, for the unwrap below.
  constexpr std::size_t kUnwritten = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> first_written(clip.joints.size(), kUnwritten);
  const auto write_rotation = [&](std::size_t f, std::size_t j, const Quatd& q) {
    motion::set_local_rotation(out.clip, f, j, q);
    first_written[j] = std::min(first_written[j], f);
  };
  std::vector<motion::JointPose> poses;
  std::vector<Quatd> global;
  double sum_sq = 0.0;
  std::size_t samples = 0;
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    if (!motion::forward_kinematics(clip, f, poses)) {
      out.error = "forward kinematics failed at frame " + std::to_string(f);
      return out;
    }
    const Vec2 shift = shift_m.empty() ? Vec2::Zero() : shift_m[f];
    const double least_drop = drop_m.empty() ? 0.0 : drop_m[f];
    const Vec2 swing = arm_swing_rad.empty() ? Vec2::Zero() : arm_swing_rad[f];
    if (f < first_frame ||
        (correction[f].norm() == 0.0 && shift.norm() == 0.0 && least_drop == 0.0 && swing.norm() == 0.0))
      continue;
    // The same turn, shift and drop the filter used, in the file's frame and units.
    const WaistTurn turn = waist_turn(human.frames[f], correction[f], shift,
                                      follow.empty() ? std::array<double, 2>{} : follow[f], least_drop);
    const Quatd r = to_int.conjugate() * turn.rotation * to_int;
    const Vec3d pivot = to_int.conjugate() * turn.pivot / g.metres_per_unit;
    const Vec3d drop = to_int.conjugate() * Vec3d(turn.shift.x(), turn.shift.y(), -turn.drop_m) / g.metres_per_unit;
    global.resize(poses.size());
    for (std::size_t j = 0; j < poses.size(); ++j) global[j] = poses[j].rotation;
    // The hips and everything on the pelvis turn rigidly: new hips rotation and position.
    const auto hu = static_cast<std::size_t>(hips);
    global[hu] = r * poses[hu].rotation;
    const Vec3d hips_pos = pivot + r * (poses[hu].position - pivot) + drop;
    const int hp = clip.joints[hu].parent;
    const Quatd parent_rot = hp >= 0 ? poses[static_cast<std::size_t>(hp)].rotation : Quatd::Identity();
    const Vec3d parent_pos = hp >= 0 ? poses[static_cast<std::size_t>(hp)].position : Vec3d::Zero();
    write_rotation(f, hu, local_from(poses, global, clip, hu));
    motion::set_local_translation(out.clip, f, hu, parent_rot.conjugate() * (hips_pos - parent_pos));
    // Below the hips every joint keeps its local rotation (its global turns
    // with the hips), except the thighs, shanks and feet the IK sets; walk the
    // hierarchy in file order so every parent's new rotation is known first.
    std::vector<int> desired(poses.size(), -1);  // index into wanted[]
    std::vector<Quatd> wanted;
    for (const bool left : {true, false}) {
      const int thigh = bone(left ? Bone::LeftUpperLeg : Bone::RightUpperLeg);
      const int shank = bone(left ? Bone::LeftLowerLeg : Bone::RightLowerLeg);
      const int foot = bone(left ? Bone::LeftFoot : Bone::RightFoot);
      const auto tu = static_cast<std::size_t>(thigh), su = static_cast<std::size_t>(shank),
                 fu = static_cast<std::size_t>(foot);
      const Vec3d hip = poses[tu].position, knee = poses[su].position, ankle = poses[fu].position;
      const Vec3d hip2 = pivot + r * (hip - pivot) + drop;
      // A swinging foot follows the pelvis by its share (the filter's turn, in the file's frame).
      const double share = turn.follow[left ? 0 : 1];
      const auto carried = [&](const Vec3d& p) { return Vec3d(p + share * (pivot + r * (p - pivot) + drop - p)); };
      const Vec3d ankle2 = carried(ankle);
      const Quatd foot_turn = to_int.conjugate() * turn.foot_turn(left ? 0 : 1) * to_int;
      const double l1 = (knee - hip).norm(), l2 = (ankle - knee).norm();
      const Vec3d d = ankle2 - hip2;
      double dist = d.norm();
      if (dist < 1e-12) continue;
      const Vec3d u = d / dist;
      dist = std::min(dist, l1 + l2);
      const double a = (l1 * l1 - l2 * l2 + dist * dist) / (2.0 * dist);
      const double h = std::sqrt(std::max(l1 * l1 - a * a, 0.0));
      // The side the filter bent this knee to, a unit vector square to the
      // same line in its frame (the file's is a turn and a scale of it).
      const auto internal = [&](const Vec3d& p) { return Vec3d(to_int * (p * g.metres_per_unit)); };
      const Vec3d v =
          to_int.conjugate() * turn.knee_side(human.frames[f], left ? 0 : 1, internal(hip2), internal(ankle2));
      const Vec3d knee2 = hip2 + a * u + h * v;
      desired[tu] = static_cast<int>(wanted.size());
      wanted.push_back(sim::quat_from_two_vectors(knee - hip, knee2 - hip2) * poses[tu].rotation);
      desired[su] = static_cast<int>(wanted.size());
      wanted.push_back(sim::quat_from_two_vectors(ankle - knee, ankle2 - knee2) * poses[su].rotation);
      desired[fu] = static_cast<int>(wanted.size());
      wanted.push_back(foot_turn * poses[fu].rotation);  // a planted foot keeps its world orientation
    }
    // Each arm's swing turns its upper arm about its shoulder joint, in the
    // world after the waist's turn (arm_swing.hpp). The chain from the hips to
    // the shoulder turned rigidly by r, so the upper arm's new world rotation is
    // the swing's times r times its old one; the forearm and hand keep their
    // local rotations and follow.
    const Vec3 left_shoulder = turn.rotation * human.frames[f].p[sim::index(Bone::LeftUpperArm)],
               right_shoulder = turn.rotation * human.frames[f].p[sim::index(Bone::RightUpperArm)];
    for (std::size_t side = 0; side < 2; ++side) {
      const Quatd swing_turn = arm_swing_turn(left_shoulder, right_shoulder, swing(static_cast<Eigen::Index>(side)));
      if (swing_turn.vec().isZero(0.0)) continue;
      const auto upper = static_cast<std::size_t>(bone(side == 0 ? Bone::LeftUpperArm : Bone::RightUpperArm));
      desired[upper] = static_cast<int>(wanted.size());
      wanted.push_back(to_int.conjugate() * swing_turn * to_int * r * poses[upper].rotation);
    }
    std::vector<bool> below(poses.size(), false);
    below[hu] = true;
    for (std::size_t j = hu + 1; j < poses.size(); ++j) {
      const int par = clip.joints[j].parent;
      if (par < 0 || !below[static_cast<std::size_t>(par)]) continue;
      below[j] = true;
      if (desired[j] >= 0) {
        global[j] = wanted[static_cast<std::size_t>(desired[j])];
        write_rotation(f, j, local_from(poses, global, clip, j));
      } else {
        global[j] = global[static_cast<std::size_t>(par)] * poses[j].local_rotation;
      }
    }
  }
  // set_local_rotation chose the angles nearest each frame's original ones,
  // which near a +-180 wrap or gimbal lock can be far from the previous
  // written frame's, and an untouched frame after a written one can be far
  // from it too. Re-expressing every frame of a written joint, from its first
  // written frame on, nearest the frame before keeps its channels continuous
  // without changing a rotation.
  for (std::size_t j = 0; j < first_written.size(); ++j) {
    if (first_written[j] != kUnwritten)
      motion::unwrap_rotation(out.clip, j, first_written[j] > 0 ? first_written[j] - 1 : 0);
  }
  // Measure what was written.
  std::vector<motion::JointPose> before, after;
  double changed_sq = 0.0;
  std::vector<double> largest(clip.joints.size(), 0.0);
  std::vector<std::size_t> largest_frame(clip.joints.size(), 0);
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    motion::forward_kinematics(clip, f, before);
    motion::forward_kinematics(out.clip, f, after);
    // The feet that carry weight stay; a swinging foot that follows the pelvis is measured apart.
    for (std::size_t side = 0; side < 2; ++side) {
      const bool swinging = !follow.empty() && follow[f][side] > 0.0;
      double& largest_here = swinging ? out.max_swing_foot_displacement_m : out.max_foot_displacement_m;
      const int tip = g.toe_tip_joint[side];
      for (const int j : {bone(side == 0 ? Bone::LeftFoot : Bone::RightFoot),
                          bone(side == 0 ? Bone::LeftToes : Bone::RightToes), tip}) {
        if (j < 0) continue;
        const auto ju = static_cast<std::size_t>(j);
        largest_here = std::max(largest_here, g.metres_per_unit * (after[ju].position - before[ju].position).norm());
      }
    }
    // Every joint, mapped or not, but only where the correction changed it:
    // averaging in untouched joints would understate the edit.
    for (std::size_t j = 0; j < after.size(); ++j) {
      const double angle = before[j].local_rotation.angularDistance(after[j].local_rotation);
      if (angle <= kChangedRad) continue;
      changed_sq += angle * angle;
      ++out.changed_samples;
      if (angle > largest[j]) {
        largest[j] = angle;
        largest_frame[j] = f;
      }
    }
    if (f < first_frame) continue;
    for (const int j : g.map.joint) {
      if (j < 0) continue;
      const auto ju = static_cast<std::size_t>(j);
      const double angle = before[ju].local_rotation.angularDistance(after[ju].local_rotation);
      sum_sq += angle * angle;
      ++samples;
    }
  }
  out.rms_change_all_mapped_joints_rad = samples > 0 ? std::sqrt(sum_sq / static_cast<double>(samples)) : 0.0;
  out.rms_change_changed_joints_rad =
      out.changed_samples > 0 ? std::sqrt(changed_sq / static_cast<double>(out.changed_samples)) : 0.0;
  for (std::size_t j = 0; j < largest.size(); ++j) {
    if (largest[j] == 0.0) continue;
    JointChange c{clip.joints[j].name, {}, largest[j], largest_frame[j]};
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      if (g.map.joint[b] == static_cast<int>(j)) c.bone = sim::kBones[b].name;
    }
    out.largest_change.push_back(std::move(c));
  }
  return out;
}

}  // namespace tonus::balance
