#include "tonus/host/reference/tracker_ik.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "body_frames.hpp"
#include "first_order.hpp"
#include "foot_steps.hpp"
#include "rig.hpp"
#include "rotations.hpp"
#include "tonus/sim/joint_limits.hpp"
#include "tracker_input.hpp"
#include "two_bone.hpp"

namespace tonus::reference {
namespace {

using detail::BodyFrames;
using detail::horizontal;
using detail::yaw_quat;
using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr std::size_t bi(Bone b) { return sim::index(b); }
constexpr std::array<Bone, 2> kUpperArm{Bone::LeftUpperArm, Bone::RightUpperArm};
constexpr std::array<Bone, 2> kClavicle{Bone::LeftShoulder, Bone::RightShoulder};
constexpr std::array<Bone, 2> kThigh{Bone::LeftUpperLeg, Bone::RightUpperLeg};
constexpr std::array<Tracker, 2> kHand{Tracker::left_hand, Tracker::right_hand};
constexpr std::array<Tracker, 2> kFootTracker{Tracker::left_foot, Tracker::right_foot};
constexpr std::array<Tracker, 2> kElbow{Tracker::left_elbow, Tracker::right_elbow};
constexpr std::array<Tracker, 2> kKnee{Tracker::left_knee, Tracker::right_knee};
constexpr int kClavicleBisections = 14;  // the share to 1e-4
constexpr double kSoftness = 0.05;       // of the smooth maxima (shares, sines)
constexpr int kTwistCorrections = 3;
constexpr int kElbowScanSteps = 6;  // 30 degrees each: half a turn either way
constexpr double kElbowScanStep_rad = std::numbers::pi / 6.0;
constexpr int kElbowBisections = 10;  // to 0.03 degrees
constexpr double kReachedTolerance_m = 1e-3;
constexpr double kPelvisKneeWeight = 0.5;
constexpr double kTwistMargin_rad = 0.05;
constexpr double kClavicleReachMargin_m = 0.005;  // see the clavicle
constexpr double kElbowStayBend = 0.4;  // of the arm's reach: the wrist this much nearer, the elbow keeps fully

// max(a, b) with the corner rounded over `soft`: never below either.
double smooth_max(double a, double b, double soft) {
  return 0.5 * (a + b + std::sqrt((a - b) * (a - b) + soft * soft));
}

// A pole direction smoothed toward `raw` and kept unit, so a weak cue (two
// that disagree, or both small) barely turns it and it never shrinks through
// zero (a flip). Starts (or restarts, if unset) at `start`.
void smooth_pole(Vec3& pole, const Vec3& raw, const Vec3& start, bool restart, double share) {
  if (restart || pole.norm() < 0.5) pole = start;
  const Vec3 moved = pole + share * (raw - pole);
  if (moved.norm() > 1e-6) pole = moved.normalized();
}

double yaw_of(const Vec3& forward, double fallback) {
  const Vec3 f = horizontal(forward);
  return f.norm() > 1e-6 ? std::atan2(f.y(), f.x()) : fallback;
}

// The solve's working set: world rotations and positions, the joints' local
// values (ball: rotation, hinge: angle) as they are settled into their ranges.
struct Work {
  BodyFrames f;
  std::array<Quat, sim::kBoneCount> local{};
  std::array<double, sim::kBoneCount> angle{};
  int clamped = 0;
};

// Sets bone b's world rotation to `world` (ball joint): its local rotation
// clamped into range, the world rotation recomputed from it.
bool settle_ball(const IkModel& m, Work& w, Bone b, const Quat& world) {
  const std::size_t i = bi(b);
  const std::size_t p = bi(*sim::kBones[i].parent);
  Quat q = (w.f.rot[p].conjugate() * world).normalized();
  const bool clamped = sim::clamp_ball(m.limit[i], q);
  if (clamped) ++w.clamped;
  w.local[i] = q;
  w.f.rot[i] = (w.f.rot[p] * q).normalized();
  return clamped;
}

void settle_hinge(const IkModel& m, Work& w, Bone b, double angle_rad) {
  const std::size_t i = bi(b);
  const std::size_t p = bi(*sim::kBones[i].parent);
  if (sim::clamp_hinge(m.limit[i], angle_rad)) ++w.clamped;
  w.angle[i] = angle_rad;
  w.local[i] = Quat(Eigen::AngleAxisd(angle_rad, m.hinge_axis[i]));
  w.f.rot[i] = (w.f.rot[p] * w.local[i]).normalized();
}

Vec3 joint_of(const Work& w, const IkModel& m, Bone b) {
  const std::size_t i = bi(b);
  const std::size_t p = bi(*sim::kBones[i].parent);
  return w.f.pos[p] + w.f.rot[p] * m.offset[i];
}

// Where the neck joint goes so the neck reaches the head joint, the spine
// and chest turned as one piece about the spine joint `base`: the middle
// joint of the two links trunk (base to the guessed neck joint) and neck,
// on the side of the guess pulled toward `back` (unit). Closed form, so a
// smooth function of its inputs, and the neck takes the head's quick moves as
// a real neck does. False (the trunk pointed straight at the head) when the
// head is out of reach.
bool reach_head(const Vec3& base, const Vec3& neck_guess, double neck_m, const Vec3& head, const Vec3& back,
                double back_weight, Vec3& neck_joint) {
  const Vec3 to_head = head - base;
  const double dist = to_head.norm();
  const double trunk_m = (neck_guess - base).norm();
  if (dist < 1e-9 || trunk_m < 1e-9) {
    neck_joint = neck_guess;
    return false;
  }
  const Vec3 u = to_head / dist;
  const double shortest = std::abs(trunk_m - neck_m), longest = trunk_m + neck_m;
  // An upright trunk and neck are nearly in line (a few mm short of their
  // length), so the guess alone names the side weakly and the neck joint
  // swung across the line with the head's sway; the neck joint is behind the
  // line from the spine to the head (the head sits forward on the neck).
  neck_joint = detail::place_middle_joint(base, u, std::clamp(dist, shortest, longest), trunk_m, neck_m,
                                          neck_guess - base + back_weight * trunk_m * back, u.unitOrthogonal())
                   .pos;
  return dist <= longest && dist >= shortest;
}

// A two-bone limb whose upper bone (under `parent`, its parent's world
// rotation) is past its ball joint's range: the middle joint (elbow, knee) is
// turned about the root-to-target line until the bone is inside, so the end
// joint stays on its target. Past its twist, the turn follows the excess
// almost one to one; past its swing cone (or still past its twist), the
// nearest place inside both is found by a scan both ways, then bisection onto
// the boundary (so it moves smoothly). `pole` and `sol` are updated.
void rescue_range(const detail::TwoBoneLimb& limb, const Vec3& root, const Vec3& target, const Vec3& fallback,
                  const Quat& parent, const sim::JointLimit& lim, Vec3& pole, detail::TwoBoneSolution& sol) {
  const Vec3 line = target - root;
  if (!lim.enabled || line.norm() <= 1e-6) return;
  const Vec3 axis = line.normalized();
  const auto local_of = [&](const detail::TwoBoneSolution& so) {
    return Quat((parent.conjugate() * so.upper).normalized());
  };
  for (int it = 0; it < kTwistCorrections; ++it) {
    const double twist = sim::swing_twist(local_of(sol), lim.twist_axis).twist_rad;
    const double excess = twist - std::clamp(twist, lim.lower_rad + kTwistMargin_rad, lim.upper_rad - kTwistMargin_rad);
    if (excess == 0.0) break;
    pole = Eigen::AngleAxisd(-excess, axis) * pole;
    sol = detail::solve_two_bone(limb, root, target, pole, fallback);
  }
  const auto outside = [&](const Vec3& p) {
    const detail::TwoBoneSolution so = detail::solve_two_bone(limb, root, target, p, fallback);
    const sim::SwingTwist sw = sim::swing_twist(local_of(so), lim.twist_axis);
    return sw.swing_rad > lim.swing_max_rad || sw.twist_rad < lim.lower_rad || sw.twist_rad > lim.upper_rad;
  };
  if (!outside(pole)) return;
  double found = 0.0;
  for (int step = 1; step <= kElbowScanSteps && found == 0.0; ++step) {
    for (const double sign : {1.0, -1.0}) {
      const double a = sign * step * kElbowScanStep_rad;
      if (found == 0.0 && !outside(Eigen::AngleAxisd(a, axis) * pole)) found = a;
    }
  }
  if (found == 0.0) return;
  double inside = found, beyond = found - std::copysign(kElbowScanStep_rad, found);
  for (int it = 0; it < kElbowBisections; ++it) {
    const double mid = 0.5 * (inside + beyond);
    (outside(Eigen::AngleAxisd(mid, axis) * pole) ? beyond : inside) = mid;
  }
  pole = Eigen::AngleAxisd(inside, axis) * pole;
  sol = detail::solve_two_bone(limb, root, target, pole, fallback);
}

// The turn about the unit `along` that takes where `before` points across it
// to where `after` does (none when either lies along it): what a range
// rescue did to a pole, for the smoothed pole to remember.
std::optional<Quat> turn_across(const Vec3& before, const Vec3& after, const Vec3& along) {
  const Vec3 a = before - before.dot(along) * along, b = after - after.dot(along) * along;
  if (a.norm() <= 1e-9 || b.norm() <= 1e-9) return std::nullopt;
  return sim::quat_from_two_vectors(a.normalized(), b.normalized());
}

}  // namespace

IkCreated make_ik_model(const sim::Model& humanoid, const BodyCalibration& calibration, const IkOptions& options) {
  IkCreated c;
  detail::Rig rig;
  if (std::string e = detail::make_rig(humanoid, rig); !e.empty()) {
    c.error = "tracker IK: " + e;
    return c;
  }
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    if (!humanoid.bodies[i].quat_in_parent.isApprox(Quat::Identity(), 1e-9)) {
      c.error = "tracker IK: the humanoid's rest frames must be parallel to the world (body " +
                std::string(sim::kBones[i].name) + " is turned)";
      return c;
    }
  }
  const IkOptions& o = options;
  const bool times_ok = o.step_time_s > 0.0 && o.step_time_min_s > 0.0 && o.step_time_min_s <= o.step_time_s &&
                        o.hold_s >= 0.0 && o.ease_s >= 0.0 && o.recover_s >= 0.0 && o.step_lead_s >= 0.0 &&
                        o.velocity_time_constant_s >= 0.0 && o.landing_follow_s >= 0.0 && o.trunk_smoothing_s >= 0.0 &&
                        o.heading_smoothing_s >= 0.0 && o.waist_heading_smoothing_s >= 0.0 &&
                        o.elbow_smoothing_s >= 0.0 && o.stride_soft_fade_s >= 0.0 && o.knee_smoothing_s >= 0.0 &&
                        o.tracked_knee_smoothing_s >= 0.0 && o.heading_smoothing2_s >= 0.0 &&
                        o.clavicle_lower_s >= 0.0 && o.chest_twist_smoothing_s >= 0.0 && o.chest_twist_lead_s >= 0.0 &&
                        o.chest_twist_lead_smoothing_s >= 0.0 && o.chest_twist_lead_speed_mps >= 0.0;
  const bool sizes_ok = o.step_threshold_m > 0.0 && o.step_turn_rad > 0.0 && o.foot_pivot_start_rad >= 0.0 &&
                        o.foot_pivot_width_rad >= 0.0 && o.step_lift_m >= 0.0 && o.trunk_turn_limit_rad >= 0.0 &&
                        o.implausible_reach_factor > 1.0 && o.leg_softness_m >= 0.0 && o.stride_softness_m >= 0.0 &&
                        o.stride_soft_speed_mps > 0.0;
  const bool shares_ok = o.pelvis_share >= 0.0 && o.spine_share >= 0.0 && o.chest_share >= 0.0 && o.neck_share >= 0.0 &&
                         o.pelvis_share <= 1.0 && o.spine_share <= 1.0 && o.trunk_follows_pelvis >= 0.0 &&
                         o.trunk_follows_pelvis <= 1.0 && o.trunk_tilts_with_pelvis >= 0.0 &&
                         o.trunk_tilts_with_pelvis <= 1.0 && o.chest_share <= 1.0 && o.neck_share <= 1.0 &&
                         o.hands_heading_weight >= 0.0 && o.neck_back_pole_weight >= 0.0 && o.clavicle_share >= 0.0 &&
                         o.clavicle_raise_share >= 0.0 && o.default_pole_weight >= 0.0 && o.elbow_stay_weight >= 0.0 &&
                         o.elbow_roll_weight >= 0.0 && o.chest_twist_reach_factor > 0.0 && o.chest_twist_max_rad >= 0.0;
  if (!(times_ok && sizes_ok && shares_ok)) {
    c.error = "tracker IK: an option is out of range (times and lengths must be positive, shares in [0, 1])";
    return c;
  }
  if (!(calibration.height_m > 0.0) || !std::isfinite(calibration.height_m)) {
    c.error = "tracker IK: the calibration has no height";
    return c;
  }
  if (!calibration.offset[index(Tracker::head)].valid) {
    c.error = "tracker IK: the calibration has no head tracker offset";
    return c;
  }
  IkModel m;
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    const sim::Body& b = humanoid.bodies[i];
    m.offset[i] = b.pos_in_parent;
    m.rest_dir[i] = rig.dir[i];
    m.hinge_axis[i] = b.hinge_axis;
    m.limit[i] = b.limit;
    m.qpos_adr[i] = b.qpos_adr;
    m.joint[i] = b.joint;
  }
  for (int i = 0; i < humanoid.nq; ++i)
    m.qpos0[static_cast<std::size_t>(i)] = humanoid.qpos0[static_cast<std::size_t>(i)];
  m.nq = humanoid.nq;
  for (std::size_t s = 0; s < 2; ++s) {
    m.upper_arm_m[s] = rig.length[bi(kUpperArm[s])];
    m.forearm_m[s] = rig.length[bi(kUpperArm[s]) + 1];
    m.thigh_m[s] = rig.length[bi(kThigh[s])];
    m.shank_m[s] = rig.length[bi(kThigh[s]) + 1];
    m.ankle_in_hips[s] = m.offset[bi(kThigh[s])] + m.offset[bi(kThigh[s]) + 1] + m.offset[bi(kThigh[s]) + 2];
  }
  m.ankle_height_m = m.offset[0].z() + 0.5 * (m.ankle_in_hips[0].z() + m.ankle_in_hips[1].z());
  m.stature_m = calibration.height_m;
  m.calibration = calibration;
  m.options = options;
  c.model = m;
  return c;
}

void solve_ik(const IkModel& m, IkState& st, const TrackerFrame& frame, IkOutput& out) {
  const IkOptions& o = m.options;
  out.flags = 0;
  out.nq = m.nq;
  ++st.stats.frames;

  double dt = 0.0;
  if (!std::isfinite(frame.time_s)) {
    out.flags |= kIkBadTime;
  } else if (st.started) {
    dt = frame.time_s - st.time_s;
    if (dt < 0.0) {
      out.flags |= kIkBadTime;
      dt = 0.0;
    }
    dt = std::min(dt, 0.1);  // a long gap is not a reason to run steps off
    st.time_s = frame.time_s;
  } else {
    st.time_s = frame.time_s;
  }

  // 1. Samples.
  for (std::size_t t = 0; t < kTrackerCount; ++t) {
    out.use[t] = TrackerUse::unused;
    if (!m.calibration.offset[t].valid) continue;
    if (!detail::read_sample(frame.pose[t], m.calibration.offset[t], dt, o, st.track[t])) {
      out.flags |= kIkTrackerInvalid;
      ++st.stats.invalid_samples;
    }
  }
  IkState::Track& head_track = st.track[index(Tracker::head)];
  if (!head_track.seen) {
    // Nothing to follow yet: the rest pose, standing at the origin.
    out.flags |= kIkNoHead;
    out.qpos = m.qpos0;
    out.qpos[2] = m.offset[0].z();
    out.head_error_m = 0.0;
    out.hand_error_m = {0.0, 0.0};
    out.foot_error_m = {0.0, 0.0};
    return;
  }
  // A lost head has no neutral: it is held where it was.
  const TrackerPose head = detail::effective_pose(head_track.held.valid ? head_track.held : head_track.shown, dt, o,
                                                  head_track, out.use[index(Tracker::head)]);

  // 2. Heading: the head's facing (its forward, or its up when it looks down),
  // pulled toward the facing the hands' line gives.
  Work w;
  const Vec3 head_fwd = horizontal(head.rot * Vec3::UnitX()) + 0.5 * horizontal(head.rot * Vec3::UnitZ());
  Vec3 facing = head_fwd.norm() > 1e-9 ? Vec3(head_fwd.normalized())
                                       : Vec3(std::cos(st.body_yaw_rad), std::sin(st.body_yaw_rad), 0.0);
  const IkState::Track& lh = st.track[index(Tracker::left_hand)];
  const IkState::Track& rh = st.track[index(Tracker::right_hand)];
  if (lh.seen && rh.seen) {
    const Vec3 l = lh.target.valid ? lh.target.pos_m : lh.shown.pos_m;
    const Vec3 r = rh.target.valid ? rh.target.pos_m : rh.shown.pos_m;
    const Vec3 across = horizontal(l - r);
    const double spread = across.norm();
    if (spread > 1e-3) {
      const Vec3 hands_fwd = across.cross(Vec3::UnitZ()) / spread;
      const double agree = std::max(0.0, hands_fwd.dot(facing));
      facing += o.hands_heading_weight * std::min(1.0, spread / 0.3) * agree * hands_fwd;
    }
  }
  double yaw = yaw_of(facing, st.body_yaw_rad);
  // The heading smoothed, so the hands' quick swings do not shake the trunk
  // (the head stays exact). 6 points: longer, as it only shapes the trunk
  // the waist tracker carries (a kick's flailing hands turned the chest), and
  // that trunk's turn from the waist is bounded (trunk_turn_limit_rad).
  // 3 points: two stages, so a quick swing's heading comes in smoothly
  // rather than with a first-order step's kink (the kicks' flailing hands).
  if (st.started) {
    const bool waist_worn = m.calibration.offset[index(Tracker::waist)].valid;
    const auto follow = [&](double from, double to, double tau) {
      return from + detail::first_order_share(dt, tau) * std::remainder(to - from, 2.0 * std::numbers::pi);
    };
    if (waist_worn) {
      yaw = follow(st.body_yaw_rad, yaw, o.waist_heading_smoothing_s);
      st.body_yaw_stage_rad = yaw;
    } else {
      st.body_yaw_stage_rad = follow(st.body_yaw_stage_rad, yaw, o.heading_smoothing_s);
      yaw = follow(st.body_yaw_rad, st.body_yaw_stage_rad, o.heading_smoothing2_s);
    }
  } else {
    st.body_yaw_stage_rad = yaw;
  }
  st.body_yaw_rad = yaw;
  const Quat heading = yaw_quat(yaw);

  // 3. Trunk: each bone takes its share of the head's turn from the heading.
  // The trunk and neck share the head's turn smoothed (its quick nods and
  // shakes are the head joint's); the head itself is exact.
  const Quat head_rel = (heading.conjugate() * head.rot).normalized();
  if (!st.started) st.trunk_turn = head_rel;
  if (st.trunk_turn.dot(head_rel) < 0.0) st.trunk_turn.coeffs() = -st.trunk_turn.coeffs();
  st.trunk_turn = st.trunk_turn.slerp(detail::first_order_share(dt, o.trunk_smoothing_s), head_rel).normalized();
  const auto share = [&](double s) { return (heading * Quat::Identity().slerp(s, st.trunk_turn)).normalized(); };
  w.f.rot[bi(Bone::Hips)] = share(o.pelvis_share);
  settle_ball(m, w, Bone::Spine, share(o.spine_share));
  settle_ball(m, w, Bone::Chest, share(o.chest_share));
  settle_ball(m, w, Bone::Neck, share(o.neck_share));
  settle_ball(m, w, Bone::Head, head.rot);
  // The pelvis that puts the head joint exactly on its target.
  Vec3 pelvis = head.pos_m;
  for (const Bone b : {Bone::Head, Bone::Neck, Bone::Chest, Bone::Spine}) {
    pelvis -= w.f.rot[bi(*sim::info(b).parent)] * m.offset[bi(b)];
  }
  w.f.pos[0] = pelvis;

  // 6 points: the pelvis from the waist tracker (eased toward the estimate
  // when lost), the spine bent to reach the head.
  IkState::Track& waist = st.track[index(Tracker::waist)];
  if (m.calibration.offset[index(Tracker::waist)].valid && waist.seen) {
    const TrackerPose estimate{pelvis, w.f.rot[0], true};
    const TrackerPose hips = detail::effective_pose(estimate, dt, o, waist, out.use[index(Tracker::waist)]);
    w.f.pos[0] = hips.pos_m;
    w.f.rot[0] = hips.rot;
    // Start from the 3-point trunk's shape, carried to the new pelvis and
    // turned with it by a share: the thorax turns against the pelvis in a
    // walk, so carrying it whole passes the pelvis's sway up the spine. The
    // pelvis's tilt and roll (its swing off the vertical) shake the chest
    // more than its turn does, so they are shared apart.
    const Quat rel = (hips.rot * share(o.pelvis_share).conjugate()).normalized();
    const Quat turn_z(Eigen::AngleAxisd(sim::swing_twist(rel, Vec3::UnitZ()).twist_rad, Vec3::UnitZ()));
    const Quat tilt = (rel * turn_z.conjugate()).normalized();
    Quat carry = (Quat::Identity().slerp(o.trunk_tilts_with_pelvis, tilt) *
                  Quat::Identity().slerp(o.trunk_follows_pelvis, turn_z))
                     .normalized();
    // The chest's turn from the pelvis about the vertical, saturated smoothly:
    // the thorax turns only so far against the pelvis, the neck does the rest.
    if (o.trunk_turn_limit_rad > 0.0) {
      const double chest_yaw = yaw_of(carry * w.f.rot[bi(Bone::Chest)] * Vec3::UnitX(), 0.0);
      const double turn =
          std::remainder(chest_yaw - yaw_of(hips.rot * Vec3::UnitX(), chest_yaw), 2.0 * std::numbers::pi);
      const double limited = o.trunk_turn_limit_rad * std::tanh(turn / o.trunk_turn_limit_rad);
      carry = (yaw_quat(limited - turn) * carry).normalized();
    }
    const Quat spine = (carry * w.f.rot[bi(Bone::Spine)]).normalized();
    const Quat chest = (carry * w.f.rot[bi(Bone::Chest)]).normalized();
    const Vec3 base = hips.pos_m + hips.rot * m.offset[bi(Bone::Spine)];
    const Vec3 guess = base + spine * m.offset[bi(Bone::Chest)] + chest * m.offset[bi(Bone::Neck)];
    Vec3 neck_joint;
    const bool reachable = reach_head(base, guess, m.offset[bi(Bone::Head)].norm(), head.pos_m, chest * -Vec3::UnitX(),
                                      o.neck_back_pole_weight, neck_joint);
    const Quat turn = sim::quat_from_two_vectors(guess - base, neck_joint - base);
    settle_ball(m, w, Bone::Spine, (turn * spine).normalized());
    settle_ball(m, w, Bone::Chest, (turn * chest).normalized());
    const Quat neck = (carry * w.f.rot[bi(Bone::Neck)]).normalized();
    settle_ball(m, w, Bone::Neck, detail::aim(neck, m.rest_dir[bi(Bone::Neck)], head.pos_m - neck_joint));
    settle_ball(m, w, Bone::Head, head.rot);
    if (!reachable) out.flags |= kIkHeadMissed;
  }
  const Vec3 pelvis_now = w.f.pos[0];
  detail::place_bones(m.offset, pelvis_now, w.f);  // trunk joints (limbs are redone below)

  // The chest twists (about its line to the neck joint, which stays put)
  // toward a hand beyond chest_twist_reach_factor times the arm's reach, by
  // what brings that shoulder back to the reach: a kick's flung arm otherwise pulls
  // the clavicle and elbow to their ends and snaps back. Capped, and smoothed
  // through two stages (a hand's quick swings are the arm's).
  {
    const Vec3 c = w.f.pos[bi(Bone::Chest)];
    const Vec3 neck_dir = m.offset[bi(Bone::Neck)];
    const Vec3 axis = neck_dir.norm() > 1e-9 ? Vec3(w.f.rot[bi(Bone::Chest)] * neck_dir.normalized())
                                             : Vec3(w.f.rot[bi(Bone::Chest)] * Vec3::UnitZ());
    const auto perp = [&](const Vec3& v) { return Vec3(v - v.dot(axis) * axis); };
    double wanted = 0.0;
    for (std::size_t s = 0; s < 2; ++s) {
      const IkState::Track& tr = st.track[index(kHand[s])];
      if (!m.calibration.offset[index(kHand[s])].valid || !tr.seen) continue;
      const Vec3 hand_now = tr.target.valid ? tr.target.pos_m : tr.shown.pos_m;
      const Vec3 shoulder = w.f.pos[bi(kClavicle[s])] + w.f.rot[bi(Bone::Chest)] * m.offset[bi(kUpperArm[s])];
      // A hand flung outward is taken a little further out (chest_twist_lead_s),
      // its speed away from this shoulder measured with the shoulder held.
      Vec3 hand_pos = hand_now;
      const double dist = (hand_now - shoulder).norm();
      if (st.started && dt > 0.0) {
        const double speed = (dist - (st.twist_hand[s] - shoulder).norm()) / dt;
        st.twist_hand_speed[s] +=
            detail::first_order_share(dt, o.chest_twist_lead_smoothing_s) * (speed - st.twist_hand_speed[s]);
        const double lead = o.chest_twist_lead_s * std::max(0.0, st.twist_hand_speed[s] - o.chest_twist_lead_speed_mps);
        if (dist > 1e-9) hand_pos = shoulder + (1.0 + lead / dist) * (hand_now - shoulder);
      } else if (!st.started) {
        st.twist_hand_speed[s] = 0.0;
      }
      st.twist_hand[s] = hand_now;
      // Beyond the factor's margin (a hanging arm is about at full reach),
      // the twist that brings the shoulder back to the arm's reach: the
      // target steps there, the two stages below make it smooth.
      const double far = m.upper_arm_m[s] + m.forearm_m[s];
      if ((hand_pos - shoulder).norm() <= o.chest_twist_reach_factor * far) continue;
      const Vec3 p = perp(shoulder - c), h = perp(hand_pos - c);
      const double r = p.norm(), big_r = h.norm();
      if (r < 1e-6 || big_r < 1e-6) continue;
      const double along = (shoulder - hand_pos).dot(axis);
      const double phi = std::atan2(axis.dot(p.cross(h)), p.dot(h));
      const double cos_needed = (r * r + big_r * big_r + along * along - far * far) / (2.0 * r * big_r);
      wanted += cos_needed >= 1.0 ? phi : phi - std::copysign(std::acos(std::max(-1.0, cos_needed)), phi);
    }
    wanted = std::clamp(wanted, -o.chest_twist_max_rad, o.chest_twist_max_rad);
    if (!st.started) st.chest_twist_rad = {wanted, wanted};
    const double a = detail::first_order_share(dt, o.chest_twist_smoothing_s);
    st.chest_twist_rad[0] += a * (wanted - st.chest_twist_rad[0]);
    st.chest_twist_rad[1] += a * (st.chest_twist_rad[0] - st.chest_twist_rad[1]);
    if (st.chest_twist_rad[1] != 0.0) {
      const Quat neck_world = w.f.rot[bi(Bone::Neck)];
      settle_ball(m, w, Bone::Chest,
                  (Quat(Eigen::AngleAxisd(st.chest_twist_rad[1], axis)) * w.f.rot[bi(Bone::Chest)]).normalized());
      settle_ball(m, w, Bone::Neck, neck_world);
      settle_ball(m, w, Bone::Head, head.rot);
      detail::place_bones(m.offset, pelvis_now, w.f);
    }
  }

  // Plausibility of the hands against the body.
  const Quat& body_yaw = heading;
  {
    const Vec3 l = body_yaw.conjugate() * (lh.target.pos_m - w.f.pos[bi(Bone::Chest)]);
    const Vec3 r = body_yaw.conjugate() * (rh.target.pos_m - w.f.pos[bi(Bone::Chest)]);
    if (lh.seen && rh.seen && lh.target.valid && rh.target.valid && l.y() < -0.15 && r.y() > 0.15) {
      out.flags |= kIkHandsSwapped;
      ++st.stats.swapped_frames;
    }
  }

  // 4. Arms.
  for (std::size_t s = 0; s < 2; ++s) {
    const Bone clav = kClavicle[s];
    const Bone upper = kUpperArm[s];
    const Bone fore = static_cast<Bone>(bi(upper) + 1);
    const Bone hand = static_cast<Bone>(bi(upper) + 2);
    const double reach = m.upper_arm_m[s] + m.forearm_m[s];
    const Quat chest = w.f.rot[bi(Bone::Chest)];
    const Vec3 clav_pos = w.f.pos[bi(clav)];
    // Neutral: hanging at the side, the hand in line with the forearm.
    const Vec3 rest_arm = m.rest_dir[bi(upper)];
    const Vec3 down = (body_yaw * Vec3(0.0, 0.15 * rest_arm.y(), -1.0)).normalized();
    const Quat hang = (body_yaw * sim::quat_from_two_vectors(rest_arm, body_yaw.conjugate() * down)).normalized();
    const Vec3 shoulder_rest = clav_pos + chest * m.offset[bi(upper)];
    const TrackerPose neutral{shoulder_rest + reach * down, hang, true};
    TrackerPose target = neutral;
    IkState::Track& tr = st.track[index(kHand[s])];
    if (m.calibration.offset[index(kHand[s])].valid) {
      target = detail::effective_pose(neutral, dt, o, tr, out.use[index(kHand[s])]);
    }
    if ((target.pos_m - shoulder_rest).norm() > o.implausible_reach_factor * reach) out.flags |= kIkImplausible;

    // Clavicle: a share of the turn that would point it at the hand, more for
    // a raised hand, and as much as the reach needs (bisection).
    const Vec3 to_hand = chest.conjugate() * (target.pos_m - clav_pos);
    const Vec3 clav_dir = m.offset[bi(upper)].normalized();
    // The turn toward the hand is a pure swing of the clavicle (about an axis
    // across its twist axis, its own direction), so a share of it is that
    // share of the angle, and the swing cone caps the share: no clamp inside
    // the bisection below.
    const Eigen::AngleAxisd full(to_hand.norm() > 1e-9 ? sim::quat_from_two_vectors(clav_dir, to_hand)
                                                       : Quat::Identity());
    const double cap = full.angle() > m.limit[bi(clav)].swing_max_rad && m.limit[bi(clav)].enabled
                           ? m.limit[bi(clav)].swing_max_rad / full.angle()
                           : 1.0;
    const double raise = smooth_max(0.0, to_hand.normalized().z(), kSoftness);
    const double wanted = std::min(1.0, o.clavicle_share + o.clavicle_raise_share * raise);
    const auto shoulder_at = [&](double kk, Quat& local) {
      local = Quat(Eigen::AngleAxisd(std::clamp(kk, -cap, cap) * full.angle(), full.axis()));
      return Vec3(clav_pos + chest * (local * m.offset[bi(upper)]));
    };
    // The least share that brings the hand within reach (0 when it is), then
    // the larger of the two, smoothly: a hard switch would jerk the shoulder
    // every time a swinging arm straightens.
    double lo = 0.0, hi = 1.0;
    Quat clav_local;
    // The reach the clavicle works to is a little short of the arm's: a
    // two-bone elbow moves as the square root of its slack near straight, so
    // the last millimetres of reach jerk it; the clavicle takes them instead.
    const double reach_c = reach - kClavicleReachMargin_m;
    if ((target.pos_m - shoulder_at(0.0, clav_local)).norm() <= reach_c) hi = 0.0;
    for (int it = 0; it < kClavicleBisections && hi > 0.0; ++it) {
      const double mid = 0.5 * (lo + hi);
      ((target.pos_m - shoulder_at(mid, clav_local)).norm() > reach_c ? lo : hi) = mid;
    }
    // Raised at once, lowered over clavicle_lower_s: a shoulder that dropped
    // as soon as the reach allowed snapped back (a kick's flung arm). Higher
    // than the reach needs is still within it.
    double k = std::min(1.0, smooth_max(wanted, hi, kSoftness));
    if (st.started && k < st.clavicle_share[s]) {
      k = st.clavicle_share[s] + detail::first_order_share(dt, o.clavicle_lower_s) * (k - st.clavicle_share[s]);
    }
    // A hand nearer the shoulder than the elbow can fold to: the clavicle
    // turns away from it (a negative share) until the folded arm reaches it,
    // rather than toward it, which left the wrist short (a kick's arm pulled
    // in). At once, as raising is.
    const sim::JointLimit& fold = m.limit[bi(fore)];
    if (fold.enabled) {
      const double flex = std::min(std::numbers::pi, std::max(std::abs(fold.lower_rad), std::abs(fold.upper_rad)));
      const double a = m.upper_arm_m[s], b = m.forearm_m[s];
      const double fold_c =
          std::sqrt(std::max(0.0, a * a + b * b + 2.0 * a * b * std::cos(flex))) + kClavicleReachMargin_m;
      if ((target.pos_m - shoulder_at(k, clav_local)).norm() < fold_c) {
        double away = -cap, near = k;  // away: far enough (or as far as the cone allows)
        for (int it = 0; it < kClavicleBisections; ++it) {
          const double mid = 0.5 * (away + near);
          ((target.pos_m - shoulder_at(mid, clav_local)).norm() < fold_c ? near : away) = mid;
        }
        k = away;
      }
    }
    st.clavicle_share[s] = k;
    shoulder_at(k, clav_local);
    settle_ball(m, w, clav, (chest * clav_local).normalized());
    const Vec3 shoulder = joint_of(w, m, upper);

    // Elbow: away from where the hand points (the least wrist bend), with
    // some of the anatomical pole (down, back, out); an elbow tracker wins.
    // Only the parts across the shoulder-wrist line count, the hand's
    // weighted by its own size: a hand pointing nearly along the arm says
    // little about the elbow, and must not flip it. The hand's roll says
    // more: the elbow is a hinge, so with the wrist untwisted the elbow's
    // axis is the hand's, and the elbow lies across the line from that axis.
    // The wrist twists widely (pronation), so it is a weak cue; without it a
    // flailing arm's elbow, placed by the pointing alone, ran into the upper
    // arm's twist range, whose boundary then swept it (the kicks).
    const Vec3 hand_dir = target.rot * m.rest_dir[bi(hand)];
    const Vec3 anatomic = chest * Vec3(-0.4, 0.3 * rest_arm.y(), -1.0);
    const Vec3 line = target.pos_m - shoulder;
    const Vec3 along = line.norm() > 1e-9 ? Vec3(line.normalized()) : Vec3(chest * -Vec3::UnitZ());
    const auto across_line = [&](const Vec3& v) { return Vec3(v - v.dot(along) * along); };
    const Vec3 hand_part = across_line(-hand_dir);
    const Vec3 roll_part = along.cross(target.rot * m.hinge_axis[bi(fore)]);  // across the line, |sin|
    const Vec3 raw_pole =
        chest.conjugate() * (hand_part.norm() * hand_part + o.default_pole_weight * across_line(anatomic.normalized()) +
                             o.elbow_roll_weight * roll_part);
    // Smoothed in the chest's frame: a hand's quick turns are the wrist's.
    // It is first carried with the shoulder-wrist line's sweep since the last
    // frame, so a whole arm swinging fast keeps its elbow's side rather than
    // dragging a cue left behind (a kick's flailing arms, 30 Hz).
    const Vec3 line_in_chest = chest.conjugate() * along;
    if (st.started && st.arm_line[s].norm() > 0.5) {
      st.elbow_pole[s] = (sim::quat_from_two_vectors(st.arm_line[s], line_in_chest) * st.elbow_pole[s]).normalized();
    }
    st.arm_line[s] = line_in_chest;
    smooth_pole(st.elbow_pole[s], raw_pole, chest.conjugate() * anatomic.normalized(), !st.started,
                detail::first_order_share(dt, o.elbow_smoothing_s));
    Vec3 pole = chest * st.elbow_pole[s];
    // A bent arm's elbow also keeps to where it was: a waving forearm turns
    // about a still elbow, which the hand's cue alone swings around. Nearly
    // straight, the elbow's side says little and the hand's cue leads.
    const Vec3 last = across_line(chest * st.elbow_last[s]);
    if (st.started && last.norm() > 1e-6) {
      const double bent = std::clamp((reach - line.norm()) / (kElbowStayBend * reach), 0.0, 1.0);
      pole = pole.normalized() + o.elbow_stay_weight * bent * last.normalized();
    }
    IkState::Track& et = st.track[index(kElbow[s])];
    if (m.calibration.offset[index(kElbow[s])].valid && et.seen) {
      const TrackerPose e = detail::effective_pose(TrackerPose{shoulder + pole, Quat::Identity(), true}, dt, o, et,
                                                   out.use[index(kElbow[s])]);
      pole = e.pos_m - shoulder;
    }
    detail::TwoBoneLimb limb{m.rest_dir[bi(upper)], m.rest_dir[bi(fore)], m.hinge_axis[bi(fore)],
                             m.upper_arm_m[s],      m.forearm_m[s],       o.arm_softness_m};
    detail::TwoBoneSolution sol = detail::solve_two_bone(limb, shoulder, target.pos_m, pole, anatomic);
    const Vec3 pole_free = pole;  // before the ranges turn it
    // An elbow the upper arm cannot twist to is turned about the shoulder-wrist
    // line until it can (the twist follows that turn almost one to one).
    rescue_range(limb, shoulder, target.pos_m, anatomic, w.f.rot[bi(clav)], m.limit[bi(upper)], pole, sol);
    // The smoothed cue remembers the turn the ranges forced (about the line),
    // so the next frame starts from the side they allow rather than crossing
    // back and being turned again (a flailing kick's arm at its twist range).
    if (const std::optional<Quat> turned = turn_across(pole_free, pole, along)) {
      st.elbow_pole[s] = (chest.conjugate() * (*turned * (chest * st.elbow_pole[s]))).normalized();
    }
    st.elbow_last[s] = chest.conjugate() * (sol.upper * m.rest_dir[bi(upper)]);
    w.f.pos[bi(upper)] = shoulder;
    double angle = sol.hinge_rad;
    if (settle_ball(m, w, upper, sol.upper)) {
      // The shoulder was clamped: re-aim the forearm from where the elbow is.
      const Vec3 elbow = shoulder + w.f.rot[bi(upper)] * m.offset[bi(fore)];
      angle = detail::angle_about(m.hinge_axis[bi(fore)], m.rest_dir[bi(fore)],
                                  w.f.rot[bi(upper)].conjugate() * (target.pos_m - elbow));
    }
    settle_hinge(m, w, fore, angle);
    settle_ball(m, w, hand, target.rot);
  }

  // 5. Legs.
  if (!st.started) st.pelvis_velocity = Vec3::Zero();
  if (st.started && dt > 0.0) {
    st.pelvis_velocity += detail::first_order_share(dt, o.velocity_time_constant_s) *
                          ((pelvis_now - st.last_pelvis) / dt - st.pelvis_velocity);
  }
  st.last_pelvis = pelvis_now;
  // The procedural legs' soft reach: in with the pelvis's speed, out when it stands.
  const double speed = horizontal(st.pelvis_velocity).norm();
  const double soft_wanted = std::isfinite(speed) ? std::clamp(speed / o.stride_soft_speed_mps, 0.0, 1.0) : 0.0;
  st.stride_soft_share = st.started ? st.stride_soft_share + detail::first_order_share(dt, o.stride_soft_fade_s) *
                                                                 (soft_wanted - st.stride_soft_share)
                                    : 0.0;
  const double pelvis_yaw = yaw_of(w.f.rot[0] * Vec3::UnitX(), yaw);
  if (!st.started) detail::plant_feet(m, st, pelvis_now, pelvis_yaw);
  std::array<Vec3, 2> hip{};
  for (std::size_t s = 0; s < 2; ++s) hip[s] = w.f.pos[0] + w.f.rot[0] * m.offset[bi(kThigh[s])];
  std::array<detail::FootTarget, 2> steps{};
  std::array<bool, 2> tracked{};
  for (std::size_t s = 0; s < 2; ++s) {
    tracked[s] = m.calibration.offset[index(kFootTracker[s])].valid && st.track[index(kFootTracker[s])].target.valid;
  }
  if (detail::advance_feet(m, st, pelvis_now, pelvis_yaw, dt, tracked, steps)) ++st.stats.steps;
  for (std::size_t s = 0; s < 2; ++s) {
    const Bone thigh = kThigh[s];
    const Bone shank = static_cast<Bone>(bi(thigh) + 1);
    const Bone foot = static_cast<Bone>(bi(thigh) + 2);
    const Bone toes = static_cast<Bone>(bi(thigh) + 3);
    if (st.foot[s].phase >= 0.0) out.flags |= kIkStepping;
    TrackerPose target{steps[s].ankle, yaw_quat(steps[s].yaw_rad), true};
    IkState::Track& ft = st.track[index(kFootTracker[s])];
    if (m.calibration.offset[index(kFootTracker[s])].valid && ft.seen) {
      target = detail::effective_pose(target, dt, o, ft, out.use[index(kFootTracker[s])]);
      if (ft.target.valid) {
        // The procedural foot follows the tracked one, ready to take over.
        st.foot[s].planted = target.pos_m;
        st.foot[s].yaw_rad = yaw_of(target.rot * Vec3::UnitX(), st.foot[s].yaw_rad);
        st.foot[s].phase = -1.0;
      }
    }
    // Knee: toward the foot's facing (its forward, or its up when the toes
    // point down, so a pointed foot does not flip the knee back), with some of
    // the pelvis's.
    const Vec3 foot_fwd = horizontal(target.rot * Vec3::UnitX()) + horizontal(target.rot * Vec3::UnitZ());
    const Vec3 pelvis_fwd = horizontal(w.f.rot[0] * Vec3::UnitX());
    Vec3 raw_knee = (foot_fwd.norm() > 1e-6 ? Vec3(foot_fwd.normalized()) : Vec3::Zero()) +
                    kPelvisKneeWeight * (pelvis_fwd.norm() > 1e-6 ? Vec3(pelvis_fwd.normalized()) : Vec3::Zero());
    // A tracked foot also names the knee's axis: its own left axis (an ankle
    // pitches about it and barely twists), so the knee goes across the leg
    // from it. The facing alone flips with a running foot's pitch.
    if (m.calibration.offset[index(kFootTracker[s])].valid && ft.seen) {
      const Vec3 leg = target.pos_m - hip[s];
      if (leg.norm() > 1e-6) raw_knee += leg.normalized().cross(target.rot * m.hinge_axis[bi(shank)]);
    }
    // Smoothed as the elbows' (a foot's quick turns are the ankle's), longer
    // over a tracked foot, whose axis rolls with the ankle. First carried, as
    // the elbow's, with the hip-ankle line's turn since the last frame, so a
    // whole leg swinging fast (a kick) keeps its knee's side rather than
    // dragging a cue left behind.
    if (const Vec3 leg = target.pos_m - hip[s]; leg.norm() > 1e-6) {
      if (st.started && st.leg_line[s].norm() > 0.5) {
        st.knee_pole[s] = (sim::quat_from_two_vectors(st.leg_line[s], leg.normalized()) * st.knee_pole[s]).normalized();
      }
      st.leg_line[s] = leg.normalized();
    }
    const bool foot_worn = m.calibration.offset[index(kFootTracker[s])].valid && ft.seen;
    smooth_pole(st.knee_pole[s], raw_knee, body_yaw * Vec3::UnitX(), !st.started,
                detail::first_order_share(dt, foot_worn ? o.tracked_knee_smoothing_s : o.knee_smoothing_s));
    Vec3 pole = st.knee_pole[s];
    IkState::Track& kt = st.track[index(kKnee[s])];
    if (m.calibration.offset[index(kKnee[s])].valid && kt.seen) {
      const TrackerPose k = detail::effective_pose(TrackerPose{hip[s] + pole, Quat::Identity(), true}, dt, o, kt,
                                                   out.use[index(kKnee[s])]);
      pole = k.pos_m - hip[s];
    }
    const bool procedural = !(m.calibration.offset[index(kFootTracker[s])].valid && ft.seen);
    const double softness = o.leg_softness_m + (procedural ? st.stride_soft_share * o.stride_softness_m : 0.0);
    detail::TwoBoneLimb limb{m.rest_dir[bi(thigh)], m.rest_dir[bi(shank)], m.hinge_axis[bi(shank)],
                             m.thigh_m[s],          m.shank_m[s],          softness};
    detail::TwoBoneSolution sol = detail::solve_two_bone(limb, hip[s], target.pos_m, pole, body_yaw * Vec3::UnitX());
    // A thigh the foot would turn past the hip's range: the knee's plane is
    // turned into it (as the elbow's), rather than the foot missed (a kick).
    const Vec3 knee_free = pole;
    rescue_range(limb, hip[s], target.pos_m, body_yaw * Vec3::UnitX(), w.f.rot[0], m.limit[bi(thigh)], pole, sol);
    const Vec3 leg = target.pos_m - hip[s];
    if (const std::optional<Quat> turned =
            leg.norm() > 1e-6 ? turn_across(knee_free, pole, leg.normalized()) : std::nullopt) {
      st.knee_pole[s] = (*turned * st.knee_pole[s]).normalized();
    }
    double angle = sol.hinge_rad;
    if (settle_ball(m, w, thigh, sol.upper)) {
      const Vec3 knee = hip[s] + w.f.rot[bi(thigh)] * m.offset[bi(shank)];
      angle = detail::angle_about(m.hinge_axis[bi(shank)], m.rest_dir[bi(shank)],
                                  w.f.rot[bi(thigh)].conjugate() * (target.pos_m - knee));
    }
    settle_hinge(m, w, shank, angle);
    settle_ball(m, w, foot, target.rot);
    settle_hinge(m, w, toes, 0.0);
  }
  st.started = true;

  // 6. The configuration, and what it reaches.
  w.f.pos[0] = pelvis_now;
  detail::place_bones(m.offset, pelvis_now, w.f);
  out.joint_pos = w.f.pos;
  out.head_error_m = (w.f.pos[bi(Bone::Head)] - head.pos_m).norm();
  for (std::size_t s = 0; s < 2; ++s) {
    out.hand_error_m[s] = (w.f.pos[bi(kUpperArm[s]) + 2] - st.track[index(kHand[s])].shown.pos_m).norm();
    out.foot_error_m[s] = (w.f.pos[bi(kThigh[s]) + 2] - steps[s].ankle).norm();
    if (m.calibration.offset[index(kFootTracker[s])].valid && st.track[index(kFootTracker[s])].seen) {
      out.foot_error_m[s] = (w.f.pos[bi(kThigh[s]) + 2] - st.track[index(kFootTracker[s])].shown.pos_m).norm();
    }
  }
  if (!m.calibration.offset[index(Tracker::left_hand)].valid) out.hand_error_m[0] = 0.0;
  if (!m.calibration.offset[index(Tracker::right_hand)].valid) out.hand_error_m[1] = 0.0;
  // A limb whose joint ranges kept it off its target is unreachable too; so
  // is a head the clamped spine missed.
  if (out.head_error_m > kReachedTolerance_m) out.flags |= kIkHeadMissed;
  for (std::size_t s = 0; s < 2; ++s) {
    if (out.hand_error_m[s] > kReachedTolerance_m) out.flags |= kIkHandUnreachable;
    if (out.foot_error_m[s] > kReachedTolerance_m) out.flags |= kIkFootUnreachable;
  }
  out.joints_clamped = w.clamped;
  if (w.clamped > 0) {
    out.flags |= kIkJointClamped;
    ++st.stats.clamped_frames;
  }
  if (out.flags & kIkImplausible) ++st.stats.implausible_frames;
  for (std::size_t t = 0; t < kTrackerCount; ++t) {
    if (out.use[t] == TrackerUse::held) out.flags |= kIkTrackerHeld;
    if (out.use[t] == TrackerUse::easing || (out.use[t] == TrackerUse::neutral && st.track[t].seen)) {
      out.flags |= kIkTrackerEased;
    }
  }

  const auto put_quat = [&](int address, const Quat& q) {
    const auto a = static_cast<std::size_t>(address);
    Quat u = q.normalized();
    const double dot = st.last_qpos[a] * u.w() + st.last_qpos[a + 1] * u.x() + st.last_qpos[a + 2] * u.y() +
                       st.last_qpos[a + 3] * u.z();
    if (dot < 0.0) u.coeffs() = -u.coeffs();
    out.qpos[a] = u.w();
    out.qpos[a + 1] = u.x();
    out.qpos[a + 2] = u.y();
    out.qpos[a + 3] = u.z();
  };
  out.qpos[0] = pelvis_now.x();
  out.qpos[1] = pelvis_now.y();
  out.qpos[2] = pelvis_now.z();
  put_quat(3, w.f.rot[0]);
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    const int adr = m.qpos_adr[i];
    if (m.joint[i] == sim::JointType::hinge) {
      out.qpos[static_cast<std::size_t>(adr)] = w.angle[i];
    } else {
      put_quat(adr, w.local[i]);
    }
  }
  bool finite = true;
  for (int i = 0; i < m.nq; ++i) finite = finite && std::isfinite(out.qpos[static_cast<std::size_t>(i)]);
  if (!finite) {
    // Never hand on a NaN: keep the last configuration.
    out.qpos = st.last_qpos;
    out.flags |= kIkTrackerInvalid;
  }
  st.last_qpos = out.qpos;
}

}  // namespace tonus::reference
