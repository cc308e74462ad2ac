#include "pose_solver.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "rotations.hpp"
#include "tonus/sim/joint_limits.hpp"

namespace tonus::reference::detail {
namespace {

using balance::Landmark;
using balance::MotionFrame;

constexpr double kMinSegment_m = 0.01;  // shorter clip segments (coincident joints) give no direction
// Weight of the twist reference in a limb's plane normal: it decides the plane
// of a nearly straight limb and costs at most about this many radians elsewhere.
constexpr double kPlaneBlend = 0.05;
// A limb bent less than this against its reference axis is overstretched, not
// bent the other way (which would turn the whole limb over).
constexpr double kOverstretch_rad = 20.0 * M_PI / 180.0;
// Calibration: enough evidence (sum of squared sines of the bend, or of
// weights) and agreement (resultant over total weight) to trust an axis.
constexpr double kMinEvidence = 1.0;
constexpr double kMinAgreement = 0.5;

struct Limb {
  Bone upper, lower, end;
};
constexpr Limb kArms[2] = {{Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand},
                           {Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand}};
constexpr Limb kLegs[2] = {{Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot},
                           {Bone::RightUpperLeg, Bone::RightLowerLeg, Bone::RightFoot}};
constexpr Bone kShoulders[2] = {Bone::LeftShoulder, Bone::RightShoulder};
constexpr Bone kToes[2] = {Bone::LeftToes, Bone::RightToes};

Vec3 at(const MotionFrame& f, Landmark l) { return f.p[balance::index(l)]; }
Vec3 at(const MotionFrame& f, Bone b) { return f.p[sim::index(b)]; }
const Quat& clip_rotation(const MotionFrame& f, Bone b) { return f.rotation[sim::index(b)]; }

std::optional<Vec3> first_away(const MotionFrame& f, const Vec3& from, std::initializer_list<Landmark> to) {
  for (const Landmark l : to) {
    const Vec3 d = at(f, l) - from;
    if (d.norm() >= kMinSegment_m) return d.normalized();
  }
  return std::nullopt;
}

// The clip's direction of bone b's segment: from its joint to the next joint
// down its chain (skipping coincident ones), or to the extremity landmark.
std::optional<Vec3> segment(const MotionFrame& f, Bone b) {
  using L = Landmark;
  const auto j = [](Bone x) { return balance::joint_of(x); };
  const Vec3 from = at(f, b);
  switch (b) {
    case Bone::Hips: return first_away(f, at(f, L::MidHip), {j(Bone::Spine), j(Bone::Chest), j(Bone::Neck)});
    case Bone::Spine: return first_away(f, from, {j(Bone::Chest), j(Bone::Neck)});
    case Bone::Chest: {  // without a chest-to-neck segment, the chest goes on straight from the spine
      const auto d = first_away(f, from, {j(Bone::Neck)});
      return d ? d : first_away(f, at(f, Bone::Spine), {j(Bone::Chest)});
    }
    case Bone::Neck: return first_away(f, from, {j(Bone::Head), L::HeadTop});
    case Bone::Head: return first_away(f, from, {L::HeadTop});
    case Bone::LeftHand: return first_away(f, from, {L::LeftHandTip});
    case Bone::RightHand: return first_away(f, from, {L::RightHandTip});
    case Bone::LeftFoot: return first_away(f, from, {j(Bone::LeftToes), L::LeftToeTip});
    case Bone::RightFoot: return first_away(f, from, {j(Bone::RightToes), L::RightToeTip});
    case Bone::LeftToes: return first_away(f, from, {L::LeftToeTip});
    case Bone::RightToes: return first_away(f, from, {L::RightToeTip});
    default: {
      const auto child = chain_child(b);
      return child ? first_away(f, from, {j(*child)}) : std::nullopt;
    }
  }
}

// A weighted mean of unit vectors seen in a clip bone's frame.
struct AxisMean {
  Vec3 sum = Vec3::Zero();
  double weight = 0.0;
  void add(const Quat& clip_rot, const Vec3& unit_world, double w) {
    sum += w * (clip_rot.conjugate() * unit_world);
    weight += w;
  }
  [[nodiscard]] std::optional<Vec3> axis() const {
    if (weight < kMinEvidence || sum.norm() < kMinAgreement * weight) return std::nullopt;
    return sum.normalized();
  }
};

}  // namespace

Calibration calibrate(const balance::HumanMotion& motion, const balance::ContactTrack& contacts) {
  std::array<AxisMean, 2> elbow, knee, hand, hand_dir, foot_standing, foot_any;
  AxisMean head;
  std::array<double, 2> pitch_sum{};
  std::array<std::size_t, 2> pitch_n{};
  for (std::size_t t = 0; t < motion.size(); ++t) {
    const MotionFrame& f = motion.frames[t];
    for (std::size_t k = 0; k < 2; ++k) {
      // The plane normal of a bent elbow or knee: its hinge axis.
      const auto bend = [&](const Limb& limb, AxisMean& upper, AxisMean* end) {
        const auto u = segment(f, limb.upper), l = segment(f, limb.lower);
        if (!u || !l) return;
        const Vec3 n = u->cross(*l);
        const double w = n.squaredNorm();
        if (w < 1e-12) return;
        upper.add(clip_rotation(f, limb.upper), n.normalized(), w);
        if (end != nullptr) end->add(clip_rotation(f, limb.end), n.normalized(), w);
      };
      bend(kArms[k], elbow[k], &hand[k]);
      bend(kLegs[k], knee[k], nullptr);
      if (const auto h = segment(f, kArms[k].end)) hand_dir[k].add(clip_rotation(f, kArms[k].end), *h, 1.0);
      // A standing foot is level: its left is horizontal, normal to its length.
      const auto d = segment(f, kLegs[k].end);
      if (!d) continue;
      const Vec3 left = Vec3::UnitZ().cross(*d);
      const bool down = t < contacts.frames.size() && contacts.frames[t][k].any();
      if (left.norm() > 1e-6)
        (down ? foot_standing : foot_any)[k].add(clip_rotation(f, kLegs[k].end), left.normalized(), left.norm());
      if (down && contacts.frames[t][k].heel && contacts.frames[t][k].ball) {
        pitch_sum[k] += std::asin(std::clamp(-d->z(), -1.0, 1.0));
        ++pitch_n[k];
      }
    }
    const Vec3 shoulders = at(f, Bone::LeftUpperArm) - at(f, Bone::RightUpperArm);
    if (shoulders.norm() >= kMinSegment_m) head.add(clip_rotation(f, Bone::Head), shoulders.normalized(), 1.0);
  }
  Calibration c;
  for (std::size_t k = 0; k < 2; ++k) {
    c.elbow_axis[k] = elbow[k].axis();
    c.knee_axis[k] = knee[k].axis();
    c.hand_axis[k] = hand[k].axis();
    c.hand_dir[k] = hand_dir[k].axis();
    c.foot_left[k] = foot_standing[k].axis();
    if (!c.foot_left[k]) c.foot_left[k] = foot_any[k].axis();
    if (pitch_n[k] > 0) c.flat_foot_pitch_rad[k] = pitch_sum[k] / static_cast<double>(pitch_n[k]);
  }
  c.head_left = head.axis();
  return c;
}

void solve_frame(const Rig& rig, const Calibration& cal, const Neutral& neutral, const MotionFrame& fr,
                 const Vec3& root_target, FrameResult& out, Neutral* measure) {
  const sim::Model& m = *rig.model;
  out.qpos = m.qpos0;
  out.clamped = {};
  std::array<Quat, sim::kBoneCount> world{};  // body rotations as set so far (after clamping)
  const auto idx = [](Bone b) { return sim::index(b); };
  const auto qip = [&](Bone b) { return rig.body(b).quat_in_parent; };
  const auto carried = [&](Bone b) {  // b's rotation with its joint at rest
    return Quat(world[idx(*sim::info(b).parent)] * qip(b));
  };
  const auto set_ball = [&](Bone b, const Quat& target) {
    const sim::Body& body = rig.body(b);
    const Quat base = carried(b);
    Quat j = (base.conjugate() * target).normalized();
    out.clamped[idx(b)] = sim::clamp_ball(body.limit, j);
    world[idx(b)] = (base * j).normalized();
    const auto a = static_cast<std::size_t>(body.qpos_adr);
    out.qpos[a] = j.w();
    out.qpos[a + 1] = j.x();
    out.qpos[a + 2] = j.y();
    out.qpos[a + 3] = j.z();
  };
  const auto set_hinge = [&](Bone b, double angle) {
    const sim::Body& body = rig.body(b);
    out.clamped[idx(b)] = sim::clamp_hinge(body.limit, angle);
    world[idx(b)] = (carried(b) * Quat(Eigen::AngleAxisd(angle, body.hinge_axis))).normalized();
    out.qpos[static_cast<std::size_t>(body.qpos_adr)] = angle;
  };
  // The hinge angle of b that points its segment closest to d.
  const auto hinge_towards = [&](const Quat& parent_world, Bone b, const Vec3& d) {
    const Quat base = parent_world * qip(b);
    return angle_about(base * rig.body(b).hinge_axis, base * rig.dir[idx(b)], d);
  };
  // b aimed along d, with its body vector s turned towards a (else the least turn from rest).
  const auto aimed = [&](Bone b, const std::optional<Vec3>& d, const Vec3& s, const std::optional<Vec3>& a) {
    Quat base = carried(b);
    if (!d) return base;
    Quat w;
    if (a && frame_match(rig.dir[idx(b)], s, *d, *a, w)) return w;
    return aim(base, rig.dir[idx(b)], *d);
  };

  // The root's or a shoulder's matched rotation with its neutral offset (or, measuring, its rest).
  const auto neutral_of = [&](Bone b, const Quat& matched, const Quat& rest) {
    if (measure == nullptr) return Quat(matched * neutral.offset[idx(b)]);
    measure->offset[idx(b)] = matched.conjugate() * rest;
    return rest;
  };

  // Root: the hip line exactly, the lumbar spine's direction as near as that allows.
  const Vec3 hip_line = at(fr, Bone::LeftUpperLeg) - at(fr, Bone::RightUpperLeg);
  Quat matched = Quat::Identity(), upright = Quat::Identity();
  frame_match(rig.lateral[0], rig.dir[0], hip_line, segment(fr, Bone::Hips).value_or(Vec3::UnitZ()), matched);
  frame_match(rig.lateral[0], rig.dir[0], hip_line, Vec3::UnitZ(), upright);
  const Quat root = neutral_of(Bone::Hips, matched, upright).normalized();
  world[0] = root;
  const Vec3 root_pos = root_target - root * rig.hip_mid;
  const auto r0 = static_cast<std::size_t>(rig.body(Bone::Hips).qpos_adr);
  for (std::size_t k = 0; k < 3; ++k) out.qpos[r0 + k] = root_pos[static_cast<Eigen::Index>(k)];
  out.qpos[r0 + 3] = root.w();
  out.qpos[r0 + 4] = root.x();
  out.qpos[r0 + 5] = root.y();
  out.qpos[r0 + 6] = root.z();

  // Trunk: the twist shared between the hip line and the shoulder line; the
  // neck halfway to the head's own facing.
  const Vec3 hips_left = hip_line.norm() > kTiny ? Vec3(hip_line.normalized()) : Vec3::UnitY();
  const Vec3 shoulder_line = at(fr, Bone::LeftUpperArm) - at(fr, Bone::RightUpperArm);
  const Vec3 chest_left = shoulder_line.norm() >= kMinSegment_m ? Vec3(shoulder_line.normalized()) : hips_left;
  set_ball(Bone::Spine,
           aimed(Bone::Spine, segment(fr, Bone::Spine), rig.lateral[idx(Bone::Spine)], Vec3(hips_left + chest_left)));
  set_ball(Bone::Chest, aimed(Bone::Chest, segment(fr, Bone::Chest), rig.lateral[idx(Bone::Chest)], chest_left));
  std::optional<Vec3> head_left;
  if (cal.head_left) head_left = clip_rotation(fr, Bone::Head) * *cal.head_left;
  const Vec3 chest_now = world[idx(Bone::Chest)] * rig.lateral[idx(Bone::Chest)];
  set_ball(Bone::Neck, aimed(Bone::Neck, segment(fr, Bone::Neck), rig.lateral[idx(Bone::Neck)],
                             head_left ? Vec3(chest_now + *head_left) : chest_now));
  set_ball(Bone::Head, aimed(Bone::Head, segment(fr, Bone::Head), rig.lateral[idx(Bone::Head)], head_left));

  // Elbow or knee: the upper bone's twist puts the hinge axis normal to the
  // limb's plane (a straight limb keeps the reference's plane); the hinge
  // angle is clamped and what it cannot do is turned into the upper bone, so
  // the limb's end still points where the clip's does.
  const auto limb = [&](const Limb& l, const std::optional<Vec3>& calibrated) {
    const auto u = segment(fr, l.upper), f = segment(fr, l.lower);
    if (!u) {
      set_ball(l.upper, carried(l.upper));
      set_hinge(l.lower, 0.0);
      return;
    }
    const Vec3 hinge_in_upper = qip(l.lower) * rig.body(l.lower).hinge_axis;
    const Quat least = aim(carried(l.upper), rig.dir[idx(l.upper)], *u);
    const auto normal_part = [&](Vec3 v) {
      v -= v.dot(*u) * *u;
      return v.norm() > 1e-6 ? std::optional<Vec3>(v.normalized()) : std::nullopt;
    };
    auto ref = normal_part(calibrated ? Vec3(clip_rotation(fr, l.upper) * *calibrated) : Vec3(least * hinge_in_upper));
    if (!ref) ref = normal_part(least * hinge_in_upper);
    Vec3 axis = ref.value_or(least * hinge_in_upper);
    if (f && ref) {
      const Vec3 n = u->cross(*f);
      const bool overstretched = n.dot(*ref) < 0.0 && std::atan2(n.norm(), u->dot(*f)) < kOverstretch_rad;
      const Vec3 blended = n + kPlaneBlend * *ref;
      if (!overstretched && blended.norm() > 1e-6) axis = blended.normalized();
    }
    Quat target = least;
    frame_match(rig.dir[idx(l.upper)], hinge_in_upper, *u, axis, target);
    if (f) {
      double angle = hinge_towards(target, l.lower, *f);
      sim::clamp_hinge(rig.body(l.lower).limit, angle);
      const Vec3 end_in_upper =
          rig.body(l.lower).pos_in_parent +
          qip(l.lower) * (Quat(Eigen::AngleAxisd(angle, rig.body(l.lower).hinge_axis)) * rig.body(l.end).pos_in_parent);
      const Vec3 want = rig.length[idx(l.upper)] * *u + rig.length[idx(l.lower)] * *f;
      target = (sim::quat_from_two_vectors(target * end_in_upper, want) * target).normalized();
    }
    set_ball(l.upper, target);
    set_hinge(l.lower, f ? hinge_towards(world[idx(l.upper)], l.lower, *f) : 0.0);
  };

  for (std::size_t k = 0; k < 2; ++k) {
    const Bone sh = kShoulders[k];
    set_ball(sh, neutral_of(sh, aimed(sh, segment(fr, sh), rig.lateral[idx(sh)], std::nullopt), carried(sh)));
    const Limb& arm = kArms[k];
    limb(arm, cal.elbow_axis[k]);
    // Hand: its direction and its pronation (against the elbow axis) from the
    // clip's hand rotation: finger joints make the tip landmark jitter.
    const Vec3 elbow_in_hand = qip(arm.end).conjugate() * rig.body(arm.lower).hinge_axis;
    const Quat& hand_rot = clip_rotation(fr, arm.end);
    std::optional<Vec3> hand_ref, hand_dir = segment(fr, arm.end);
    if (cal.hand_axis[k]) hand_ref = hand_rot * *cal.hand_axis[k];
    if (cal.hand_dir[k]) hand_dir = hand_rot * *cal.hand_dir[k];
    set_ball(arm.end, aimed(arm.end, hand_dir, elbow_in_hand, hand_ref));
  }
  for (std::size_t k = 0; k < 2; ++k) {
    const Limb& leg = kLegs[k];
    limb(leg, cal.knee_axis[k]);
    // Foot: its roll from the clip's foot (calibrated level while it stands), else level.
    const auto d = segment(fr, leg.end);
    std::optional<Vec3> foot_ref;
    if (cal.foot_left[k]) {
      foot_ref = clip_rotation(fr, leg.end) * *cal.foot_left[k];
    } else if (d) {
      foot_ref = Vec3::UnitZ().cross(*d);
    }
    const Quat level(Eigen::AngleAxisd(-neutral.foot_pitch_rad[k], rig.lateral[idx(leg.end)]));
    set_ball(leg.end, aimed(leg.end, d, rig.lateral[idx(leg.end)], foot_ref) * level);
    // Toes: the clip's toe joint turning about the foot's left axis (its toe
    // landmarks often only continue the foot's line), else the landmarks.
    const auto toes = segment(fr, kToes[k]);
    if (cal.foot_left[k]) {
      const Quat rel = clip_rotation(fr, leg.end).conjugate() * clip_rotation(fr, kToes[k]);
      out.toe_matched_rad[k] = sim::swing_twist(rel, *cal.foot_left[k]).twist_rad;
    } else {
      out.toe_matched_rad[k] = toes ? hinge_towards(world[idx(leg.end)], kToes[k], *toes) : neutral.toe_rad[k];
    }
    set_hinge(kToes[k], out.toe_matched_rad[k] - neutral.toe_rad[k]);
  }
}

}  // namespace tonus::reference::detail
