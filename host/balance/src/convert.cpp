// BVH clip -> HumanMotion. Proportions used to synthesise missing
// extremities are de Leva's (1996) segment lengths and Winter's (2009) foot
// geometry; docs/balance.md lists them.
#include "tonus/host/balance/convert.hpp"

#include <cmath>
#include <limits>

#include "tonus/sim/anthropometry.hpp"

namespace tonus::balance {
namespace {

using sim::Bone;
using sim::Segment;

constexpr double kTypicalLegM = 0.85;  // hip to ankle joint centre of an adult

double de_leva_len(Segment s) { return sim::de_leva(s, sim::Sex::male).length_m; }

// Winter: foot 0.152 H, hip to ankle 0.491 H.
double foot_length_m(double thigh_m, double shank_m) { return 0.152 / (0.530 - 0.039) * (thigh_m + shank_m); }

struct Unit {
  const char* name;
  double metres;
};
constexpr Unit kUnits[] = {
    {"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"inch", 0.0254}, {"CMU unit (0.056444 m)", 0.056444}};

Vec3 to_internal(const Eigen::Vector3d& p) { return {p.z(), p.x(), p.y()}; }

int joint_of_bone(const SkeletonMap& m, Bone b) { return m.joint[sim::index(b)]; }

// The descendant (End Sites included) farthest from `joint` at rest offsets.
int farthest_descendant(const motion::Clip& clip, int joint) {
  int best = -1;
  double best_d = 0.0;
  std::vector<Eigen::Vector3d> rel(clip.joints.size(), Eigen::Vector3d::Zero());
  std::vector<bool> below(clip.joints.size(), false);
  below[static_cast<std::size_t>(joint)] = true;
  for (std::size_t j = static_cast<std::size_t>(joint) + 1; j < clip.joints.size(); ++j) {
    const int p = clip.joints[j].parent;
    if (p < 0 || !below[static_cast<std::size_t>(p)]) continue;
    below[j] = true;
    rel[j] = rel[static_cast<std::size_t>(p)] + clip.joints[j].offset;
    if (rel[j].norm() > best_d) {
      best_d = rel[j].norm();
      best = static_cast<int>(j);
    }
  }
  return best;
}

// The End Site child of a joint, when its OFFSET is not zero (Bandai's are all zero).
int real_end_site(const motion::Clip& clip, int joint, double min_len) {
  for (std::size_t j = static_cast<std::size_t>(joint) + 1; j < clip.joints.size(); ++j) {
    if (clip.joints[j].parent == joint && clip.joints[j].end_site && clip.joints[j].offset.norm() > min_len) {
      return static_cast<int>(j);
    }
  }
  return -1;
}

double max_rotation_change(const SkeletonMap& map, const std::vector<motion::JointPose>& a,
                           const std::vector<motion::JointPose>& b) {
  double worst = 0.0;
  for (std::size_t bone = 1; bone < sim::kBoneCount; ++bone) {
    const int j = map.joint[bone];
    if (j < 0) continue;
    worst = std::max(worst, a[static_cast<std::size_t>(j)].local_rotation.angularDistance(
                                b[static_cast<std::size_t>(j)].local_rotation));
  }
  return worst;
}

}  // namespace

Quat file_to_internal() {
  Eigen::Matrix3d c;
  c << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  return Quat(c);
}

namespace {

// The landmarks a skeleton lacks, from the bones it has (`have`; their joint
// positions and rotations already in `out`). `pos` gives a file joint's
// position (internal frame, metres): the End Sites `g` names.
template <class JointPosition>
void synthesise_landmarks(const SkeletonGeometry& g, const std::array<bool, sim::kBoneCount>& have,
                          const JointPosition& pos, MotionFrame& out) {
  auto& p = out.p;
  const auto P = [&](Bone b) -> Vec3& { return p[sim::index(b)]; };
  const auto R = [&](Bone b) -> Quat& { return out.rotation[sim::index(b)]; };
  p[index(Landmark::MidHip)] = 0.5 * (P(Bone::LeftUpperLeg) + P(Bone::RightUpperLeg));
  const Vec3 midhip = p[index(Landmark::MidHip)];
  // Neck and head: at least one exists.
  if (!have[sim::index(Bone::Neck)]) {
    P(Bone::Neck) = P(Bone::Head);
    R(Bone::Neck) = R(Bone::Head);
  }
  const double head_len = de_leva_len(Segment::head) / de_leva_len(Segment::thigh) * g.thigh_m;
  if (!have[sim::index(Bone::Head)]) {
    const Vec3 up = (P(Bone::Neck) - midhip).normalized();
    P(Bone::Head) = P(Bone::Neck) + 0.3 * head_len * up;
    R(Bone::Head) = R(Bone::Neck);
  }
  // Spine joints a skeleton lacks: on the line from the hips to the neck.
  if (!have[sim::index(Bone::Spine)]) {
    P(Bone::Spine) = midhip + (P(Bone::Neck) - midhip) / 3.0;
    R(Bone::Spine) = R(Bone::Hips);
  }
  if (!have[sim::index(Bone::Chest)]) {
    P(Bone::Chest) = midhip + 2.0 * (P(Bone::Neck) - midhip) / 3.0;
    R(Bone::Chest) = R(Bone::Spine);
  }
  for (const Bone sh : {Bone::LeftShoulder, Bone::RightShoulder}) {
    const Bone arm = static_cast<Bone>(sim::index(sh) + 1);
    if (!have[sim::index(sh)]) {
      P(sh) = P(arm);
      R(sh) = R(Bone::Chest);
    }
  }
  // Head top: the file's End Site, or de Leva's head length up the neck-head line.
  if (g.head_top_joint >= 0) {
    p[index(Landmark::HeadTop)] = pos(g.head_top_joint);
  } else {
    Vec3 up = P(Bone::Head) - P(Bone::Neck);
    if (up.norm() < 1e-6) up = P(Bone::Neck) - midhip;
    p[index(Landmark::HeadTop)] = P(Bone::Neck) + head_len * up.normalized();
  }
  // Hands: de Leva's hand ends at the third metacarpale, 46 % of the way to the fingertip.
  const double met3_share = de_leva_len(Segment::hand) / (0.108 * sim::kDeLevaMaleSubject.stature_m);
  const Landmark tips[2] = {Landmark::LeftHandTip, Landmark::RightHandTip};
  const Bone hands[2] = {Bone::LeftHand, Bone::RightHand}, forearms[2] = {Bone::LeftLowerArm, Bone::RightLowerArm};
  for (std::size_t k = 0; k < 2; ++k) {
    const Vec3 wrist = P(hands[k]);
    if (g.hand_far_joint[k] >= 0 && (pos(g.hand_far_joint[k]) - wrist).norm() > 0.01) {
      p[index(tips[k])] = wrist + met3_share * (pos(g.hand_far_joint[k]) - wrist);
    } else {
      const Vec3 dir = (wrist - P(forearms[k])).normalized();
      p[index(tips[k])] = wrist + de_leva_len(Segment::hand) / de_leva_len(Segment::forearm) * g.forearm_m * dir;
    }
  }
  // Feet: the toes, the toe tip and the heel, from Winter's foot proportions.
  const Vec3 left = P(Bone::LeftUpperLeg) - P(Bone::RightUpperLeg);
  const Vec3 forward_body = Vec3(left.x(), left.y(), 0.0).cross(Vec3::UnitZ()).normalized();
  for (const Foot foot : {Foot::left, Foot::right}) {
    const auto k = static_cast<std::size_t>(foot);
    const FootLandmarks f = foot_landmarks(foot);
    const Bone toes_bone = foot == Foot::left ? Bone::LeftToes : Bone::RightToes;
    const Bone foot_bone = foot == Foot::left ? Bone::LeftFoot : Bone::RightFoot;
    const Vec3 ankle = p[index(f.ankle)];
    const double ankle_height = 0.16 * g.shank_m;  // Winter: ankle 0.039 H above the sole, shank 0.246 H
    if (!have[sim::index(toes_bone)]) {
      p[index(f.toe_joint)] = ankle + 0.56 * g.foot_m * forward_body - Vec3(0, 0, 0.75 * ankle_height);
      R(toes_bone) = R(foot_bone);
    }
    const Vec3 ball = p[index(f.toe_joint)];
    Vec3 fwd(ball.x() - ankle.x(), ball.y() - ankle.y(), 0.0);
    fwd = fwd.norm() > 1e-6 ? Vec3(fwd.normalized()) : forward_body;
    if (g.toe_tip_joint[k] >= 0) {
      p[index(f.toe_tip)] = pos(g.toe_tip_joint[k]);
    } else {
      Vec3 dir = ball - ankle;
      dir = dir.norm() > 1e-6 ? Vec3(dir.normalized()) : fwd;
      p[index(f.toe_tip)] = ball + (0.77 - 0.56) * g.foot_m * dir;
    }
    p[index(f.heel)] = ankle - 0.23 * g.foot_m * fwd - Vec3(0, 0, ankle_height);
  }
}

}  // namespace

void landmarks_from_poses(const SkeletonGeometry& g, const std::vector<motion::JointPose>& poses, MotionFrame& out) {
  const Quat c = file_to_internal();
  const double s = g.metres_per_unit;
  const auto pos = [&](int j) { return Vec3(s * to_internal(poses[static_cast<std::size_t>(j)].position)); };
  std::array<bool, sim::kBoneCount> have{};
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    const int j = g.map.joint[b];
    have[b] = j >= 0;
    if (j >= 0) {
      out.p[b] = pos(j);
      out.rotation[b] = c * poses[static_cast<std::size_t>(j)].rotation * c.conjugate();
    }
  }
  synthesise_landmarks(g, have, pos, out);
}

SkeletonGeometry geometry_from_lengths(double thigh_m, double shank_m, double forearm_m) {
  SkeletonGeometry g;
  g.map.joint.fill(-1);
  g.thigh_m = thigh_m;
  g.shank_m = shank_m;
  g.forearm_m = forearm_m;
  g.foot_m = foot_length_m(thigh_m, shank_m);
  return g;
}

void landmarks_from_bones(const SkeletonGeometry& g, const std::array<bool, sim::kBoneCount>& have,
                          MotionFrame& frame) {
  // No End Site is named (geometry_from_lengths), so no file joint is asked for.
  const auto none = [&](int) { return Vec3(Vec3::Zero()); };
  SkeletonGeometry bare = g;
  bare.head_top_joint = -1;
  bare.hand_far_joint[0] = bare.hand_far_joint[1] = -1;
  bare.toe_tip_joint[0] = bare.toe_tip_joint[1] = -1;
  synthesise_landmarks(bare, have, none, frame);
}

Conversion convert_motion(const motion::Clip& clip, const MapResult& mapping, const ConvertOptions& opt) {
  Conversion r;
  if (!mapping.ok()) {
    r.error = mapping.error;
    return r;
  }
  if (clip.frame_count < 2) {
    r.error = "the clip needs at least two frames";
    return r;
  }
  SkeletonGeometry& g = r.geometry;
  g.map = mapping.map;
  for (const std::string& n : mapping.notes) r.messages.push_back(n);
  std::vector<motion::JointPose> poses;
  if (!motion::forward_kinematics(clip, 0, poses)) {
    r.error = "the clip's hierarchy or values are malformed";
    return r;
  }
  // Bone lengths in file units (from the rest offsets: the same in every frame).
  const auto length = [&](Bone from, Bone to) {
    const int a = joint_of_bone(g.map, from), b = joint_of_bone(g.map, to);
    return (poses[static_cast<std::size_t>(a)].position - poses[static_cast<std::size_t>(b)].position).norm();
  };
  const double thigh =
      0.5 * (length(Bone::LeftUpperLeg, Bone::LeftLowerLeg) + length(Bone::RightUpperLeg, Bone::RightLowerLeg));
  const double shank =
      0.5 * (length(Bone::LeftLowerLeg, Bone::LeftFoot) + length(Bone::RightLowerLeg, Bone::RightFoot));
  const double forearm =
      0.5 * (length(Bone::LeftLowerArm, Bone::LeftHand) + length(Bone::RightLowerArm, Bone::RightHand));
  if (!(thigh + shank > 0.0) || !std::isfinite(thigh + shank)) {
    r.error = "the legs have no length (hip, knee and ankle joints coincide)";
    return r;
  }
  if (opt.metres_per_unit) {
    if (!(*opt.metres_per_unit > 0.0) || !std::isfinite(*opt.metres_per_unit)) {
      r.error = "the unit must be a positive number of metres";
      return r;
    }
    g.metres_per_unit = *opt.metres_per_unit;
    r.unit_name = "given";
  } else {
    double best = std::numeric_limits<double>::infinity();
    for (const Unit& u : kUnits) {
      const double miss = std::abs(std::log((thigh + shank) * u.metres / kTypicalLegM));
      if (miss < best) {
        best = miss;
        g.metres_per_unit = u.metres;
        r.unit_name = u.name;
      }
    }
    r.unit_guessed = true;
    const double leg = (thigh + shank) * g.metres_per_unit;
    r.messages.push_back("unit guessed from the leg length: " + r.unit_name + " (hip to ankle " +
                         std::to_string(leg).substr(0, 5) + " m); give the unit to override");
    if (std::abs(std::log(leg / kTypicalLegM)) > std::log(1.6)) {
      r.messages.push_back("warning: no usual unit gives a human leg length; the guess may be wrong");
    }
  }
  const double s = g.metres_per_unit;
  g.thigh_m = thigh * s;
  g.shank_m = shank * s;
  g.forearm_m = forearm * s;
  g.foot_m = foot_length_m(g.thigh_m, g.shank_m);
  const int head =
      joint_of_bone(g.map, Bone::Head) >= 0 ? joint_of_bone(g.map, Bone::Head) : joint_of_bone(g.map, Bone::Neck);
  g.head_top_joint = real_end_site(clip, head, 0.02 / s);
  g.hand_far_joint[0] = farthest_descendant(clip, joint_of_bone(g.map, Bone::LeftHand));
  g.hand_far_joint[1] = farthest_descendant(clip, joint_of_bone(g.map, Bone::RightHand));
  for (std::size_t k = 0; k < 2; ++k) {
    const int toes = joint_of_bone(g.map, k == 0 ? Bone::LeftToes : Bone::RightToes);
    g.toe_tip_joint[k] = toes >= 0 ? real_end_site(clip, toes, 0.01 / s) : -1;
  }

  HumanMotion& m = r.motion;
  m.dt_s = clip.frame_time_s;
  m.frames.resize(clip.frame_count);
  std::vector<motion::JointPose> first, second, third;
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    motion::forward_kinematics(clip, f, poses);
    landmarks_from_poses(g, poses, m.frames[f]);
    if (f == 0) first = poses;
    if (f == 1) second = poses;
    if (f == 2) third = poses;
  }
  // A leading T-pose: frame 0 far from frame 1 (a jump of over 45 degrees in some
  // joint, where frames 1 and 2 differ by under 10), arms horizontal in frame 0.
  if (opt.exclude_tpose && clip.frame_count >= 3) {
    const double jump = max_rotation_change(g.map, first, second), next = max_rotation_change(g.map, second, third);
    const MotionFrame& f0 = m.frames[0];
    const auto arm_level = [&](Bone upper, Bone lower) {
      const Vec3 d = (f0.p[sim::index(lower)] - f0.p[sim::index(upper)]).normalized();
      return std::abs(d.z()) < 0.35;
    };
    const bool arms_out =
        arm_level(Bone::LeftUpperArm, Bone::LeftLowerArm) && arm_level(Bone::RightUpperArm, Bone::RightLowerArm);
    if (jump > M_PI / 4.0 && next < M_PI / 18.0 && arms_out) {
      m.first_frame = 1;
      r.tpose_excluded = true;
      r.messages.push_back("frame 0 is a T-pose (arms level, " + std::to_string(static_cast<int>(jump * 180.0 / M_PI)) +
                           " degrees from frame 1): excluded from the analysis");
    }
  }
  return r;
}

}  // namespace tonus::balance
