// The tracker IK against a ground-truth humanoid posed by hand, its trackers
// read off sim's forward kinematics (not the solver's own), and sim's
// kinematics of the solution.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "ik_fixtures.hpp"
#include "tonus/sim/joint_limits.hpp"

namespace tonus::reference::test {
namespace {

using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr double kMm = 1e-3;

std::array<Vec3, sim::kBoneCount> truth_joints(const IkRig& rig) {
  std::array<Vec3, sim::kBoneCount> j{};
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) j[b] = rig.truth_data->xbody[b].pos;
  return j;
}

double mean_joint_error(const std::array<Vec3, sim::kBoneCount>& a, const std::array<Vec3, sim::kBoneCount>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) s += (a[i] - b[i]).norm();
  return s / static_cast<double>(sim::kBoneCount);
}

bool all_finite(const IkOutput& out) {
  for (int i = 0; i < out.nq; ++i) {
    if (!std::isfinite(out.qpos[static_cast<std::size_t>(i)])) return false;
  }
  return true;
}

// The humanoid with its arms turned down by `angle` (an A-pose at 0.7).
std::array<double, sim::kMaxQpos> arms_down(const sim::Model& m, double angle) {
  auto q = m.qpos0;
  for (const Bone b : {Bone::LeftUpperArm, Bone::RightUpperArm}) {
    const double sign = b == Bone::LeftUpperArm ? -1.0 : 1.0;
    const Quat r(Eigen::AngleAxisd(sign * angle, Vec3::UnitX()));
    const auto a = static_cast<std::size_t>(m.bodies[sim::index(b)].qpos_adr);
    q[a] = r.w();
    q[a + 1] = r.x();
    q[a + 2] = r.y();
    q[a + 3] = r.z();
  }
  return q;
}

TEST_CASE("calibration: stature, arm length and heading from a T- or A-pose") {
  for (const double height : {1.55, 1.70, 1.90}) {
    for (const double arm_angle : {0.0, 0.7}) {
      for (const double yaw : {0.0, 2.2}) {
        CAPTURE(height);
        CAPTURE(arm_angle);
        CAPTURE(yaw);
        IkRig rig = make_ik_rig(height, 6);
        auto q = arms_down(*rig.truth, arm_angle);
        const Quat r(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
        q[3] = r.w();
        q[6] = r.z();
        q[0] = 0.7;
        q[1] = -1.3;
        const CalibrationResult cal = calibrate(pose_truth(rig, q, 0.0));
        REQUIRE_MESSAGE(cal.ok(), cal.error);
        // The headset sits 4 mm below the eyes the 0.936 rule assumes: a few mm of stature.
        CHECK(cal.body.height_m == doctest::Approx(height).epsilon(0.01));
        CHECK(cal.body.arm_scale == doctest::Approx(1.0).epsilon(0.03));
        CHECK(std::abs(std::remainder(cal.body.yaw_rad - yaw, 2.0 * std::numbers::pi)) < 0.01);
        // The controllers sit 2.5 cm below the wrist line: the arms read 0.06 rad low.
        CHECK(std::abs(cal.body.arm_angle_rad - arm_angle) < 0.07);
        // Arm span: the truth's wrists apart in a T-pose plus two hands (0.108 H, as sim's humanoid).
        const TrackerFrame t_pose = pose_truth(rig, rig.truth->qpos0, 0.0);
        (void)t_pose;
        const double span = (rig.truth_data->xbody[sim::index(Bone::LeftHand)].pos -
                             rig.truth_data->xbody[sim::index(Bone::RightHand)].pos)
                                .norm() +
                            2.0 * 0.108 * height;
        CHECK(cal.body.arm_span_m == doctest::Approx(span).epsilon(0.02));
        for (const Tracker t : {Tracker::head, Tracker::left_hand, Tracker::right_hand, Tracker::waist,
                                Tracker::left_foot, Tracker::right_foot}) {
          CAPTURE(tracker_name(t));
          REQUIRE(cal.body.offset[index(t)].valid);
          // The offsets come back within the calibration's assumptions (body centred between the hands).
          CHECK((cal.body.offset[index(t)].pos_m - rig.worn[index(t)].pos_m).norm() < 0.04);
          CHECK(cal.body.offset[index(t)].rot.angularDistance(rig.worn[index(t)].rot) < 0.07);
        }
      }
    }
  }
}

TEST_CASE("calibration: long arms are measured") {
  sim::HumanoidSpec spec;
  auto o = sim::default_skeleton(1.75);
  for (const Bone b : {Bone::LeftLowerArm, Bone::LeftHand, Bone::RightLowerArm, Bone::RightHand}) {
    o[sim::index(b)] *= 1.12;
  }
  spec.height_m = 1.75;
  spec.bone_offsets = o;
  sim::BuildResult truth = sim::build_humanoid(spec);
  REQUIRE(truth);
  IkRig rig = make_ik_rig(1.75, 3);
  rig.truth = std::move(truth.model);
  rig.truth_data = sim::make_data(*rig.truth);
  const CalibrationResult cal = calibrate(pose_truth(rig, rig.truth->qpos0, 0.0));
  REQUIRE(cal.ok());
  CHECK(cal.body.arm_scale == doctest::Approx(1.12).epsilon(0.02));
}

TEST_CASE("calibration: a sample that is not a standing performer is refused") {
  IkRig rig = make_ik_rig(1.70, 3);
  const TrackerFrame good = pose_truth(rig, rig.truth->qpos0, 0.0);
  TrackerFrame f = good;
  f[Tracker::head].pos_m.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(calibrate(f).ok());
  f = good;
  f[Tracker::left_hand].valid = false;
  CHECK_FALSE(calibrate(f).ok());
  f = good;
  f[Tracker::left_hand].pos_m = f[Tracker::right_hand].pos_m + Vec3(0.05, 0.0, 0.0);
  CHECK(calibrate(f).error.find("apart") != std::string::npos);
  f = good;
  for (TrackerPose& p : f.pose) p.pos_m.z() += 3.0;  // the floor is not at z = 0
  CHECK(calibrate(f).error.find("stature") != std::string::npos);
  f = good;
  f[Tracker::left_hand].pos_m.y() += 1.0;  // a controller put down, not held
  CHECK(calibrate(f).error.find("arms") != std::string::npos);
}

TEST_CASE("tracker IK: the calibration pose solves back to itself") {
  for (const int count : {3, 6}) {
    for (const bool exact : {true, false}) {
      CAPTURE(count);
      CAPTURE(exact);
      IkRig rig = make_ik_rig(1.70, count, {}, exact);
      IkState state;
      IkOutput out;
      const TrackerFrame frame = pose_truth(rig, rig.truth->qpos0, 0.0);
      const auto truth = truth_joints(rig);
      solve_ik(*rig.ik, state, frame, out);
      const auto j = solved_joints(rig, out.qpos);
      // Exact offsets: the pose itself, but for the straight arms' soft reach (elbows bent by a few degrees);
      // calibrated: within what the calibration assumes (1-2 cm).
      CHECK(mean_joint_error(j, truth) < (exact ? 0.003 : 0.02));
      for (const Bone b : {Bone::Hips, Bone::Head, Bone::LeftFoot, Bone::RightFoot}) {
        CHECK((j[sim::index(b)] - truth[sim::index(b)]).norm() < (exact ? 1e-6 : 0.02));
      }
      CHECK((j[sim::index(Bone::Head)] - bone_target(rig, frame, Tracker::head)).norm() < kMm);
      CHECK((j[sim::index(Bone::LeftHand)] - bone_target(rig, frame, Tracker::left_hand)).norm() < kMm);
      CHECK((j[sim::index(Bone::RightHand)] - bone_target(rig, frame, Tracker::right_hand)).norm() < kMm);
      CHECK((out.flags & (kIkHandUnreachable | kIkImplausible | kIkHandsSwapped)) == 0);
    }
  }
}

TEST_CASE("tracker IK: head and hands within 1 mm of reachable targets, every joint within its range") {
  for (const int count : {3, 6}) {
    CAPTURE(count);
    IkRig rig = make_ik_rig(1.70, count, {}, true);
    int reached = 0, poses = 0;
    double worst_reached = 0.0, worst_pelvis = 0.0, worst_ankle = 0.0;
    for (std::uint32_t seed = 1; seed <= 300; ++seed) {
      const auto q = random_pose(*rig.truth, seed, 0.6, Vec3(0.3, -0.2, 0.85));
      const TrackerFrame frame = pose_truth(rig, q, 0.0);
      IkState state;  // each pose on its own: no history to lean on
      IkOutput out;
      solve_ik(*rig.ik, state, frame, out);
      REQUIRE(all_finite(out));
      const auto j = solved_joints(rig, out.qpos);
      ++poses;
      const double head = (j[sim::index(Bone::Head)] - bone_target(rig, frame, Tracker::head)).norm();
      const double left = (j[sim::index(Bone::LeftHand)] - bone_target(rig, frame, Tracker::left_hand)).norm();
      const double right = (j[sim::index(Bone::RightHand)] - bone_target(rig, frame, Tracker::right_hand)).norm();
      if (!(out.flags & (kIkHandUnreachable | kIkHeadMissed))) {
        ++reached;
        worst_reached = std::max({worst_reached, head, left, right});
      }
      if (count == 3) CHECK(head < kMm);  // 3 points: the pelvis is placed so the head is always reached
      if (count == 6) {
        worst_pelvis = std::max(worst_pelvis, (j[0] - rig.truth_data->xbody[0].pos).norm());
        if (!(out.flags & kIkFootUnreachable)) {
          for (const Bone foot : {Bone::LeftFoot, Bone::RightFoot}) {
            worst_ankle =
                std::max(worst_ankle, (j[sim::index(foot)] - rig.truth_data->xbody[sim::index(foot)].pos).norm());
          }
        }
      }
      // The solution needs no clamping: it is inside every range already.
      auto copy = out.qpos;
      sim::clamp_to_limits(*rig.solved, copy);
      double moved = 0.0;
      for (int i = 0; i < out.nq; ++i) {
        moved = std::max(moved, std::abs(copy[static_cast<std::size_t>(i)] - out.qpos[static_cast<std::size_t>(i)]));
      }
      CHECK(moved < 1e-9);  // joints on a boundary may re-clamp by rounding, no more
    }
    MESSAGE("reached " << reached << " of " << poses << " random poses; worst reached error " << worst_reached * 1e3
                       << " mm");
    CHECK(worst_reached < kMm);
    CHECK(reached >= 150);  // the rest ask for an arm or spine the ranges forbid, or (3 points) a bent trunk
    if (count == 6) {
      CHECK(worst_pelvis < kMm);
      CHECK(worst_ankle < kMm);
    }
  }
}

// A stream: the truth's rest pose carried along a path, head turning.
struct Walker {
  IkRig& rig;
  IkState state;
  IkOutput out;
  TrackerFrame frame;
  void at(double t, const Vec3& root, double yaw, double crouch_m = 0.0) {
    auto q = rest_qpos(*rig.truth, root - Vec3(0.0, 0.0, crouch_m), yaw);
    frame = pose_truth(rig, q, t);
    solve_ik(*rig.ik, state, frame, out);
  }
};

TEST_CASE("tracker IK: continuous over a full turn, deterministic") {
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  Walker a{rig, {}, {}, {}}, b{rig, {}, {}, {}};
  std::array<double, sim::kMaxQpos> last{};
  double worst_jump = 0.0;
  for (int k = 0; k <= 4000; ++k) {
    const double t = 1e-3 * k;
    const double yaw = 2.0 * std::numbers::pi * t / 4.0 + 0.3;  // a whole turn in 4 s
    a.at(t, Vec3(0.0, 0.0, 0.91), yaw);
    b.at(t, Vec3(0.0, 0.0, 0.91), yaw);
    REQUIRE(a.out.qpos == b.out.qpos);
    if (k > 0) {
      for (int i = 0; i < a.out.nq; ++i) {
        worst_jump =
            std::max(worst_jump, std::abs(a.out.qpos[static_cast<std::size_t>(i)] - last[static_cast<std::size_t>(i)]));
      }
    }
    last = a.out.qpos;
  }
  // 1 ms steps of a 1.57 rad/s turn: no entry may jump (a sign flip would be ~2;
  // the largest seen, 0.06, is a foot's first frame of a step).
  CHECK(worst_jump < 0.1);
  CHECK(a.state.stats.steps >= 4);  // the feet stepped round with the body
}

TEST_CASE("tracker IK: crouching bends the knees and keeps the feet on the floor") {
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  Walker w{rig, {}, {}, {}};
  const double ankle_z = w.rig.ik->ankle_height_m;
  for (int k = 0; k <= 1000; ++k) w.at(1e-3 * k, Vec3(0.0, 0.0, 0.901), 0.0, 0.4 * k / 1000.0);
  const auto j = solved_joints(rig, w.out.qpos);
  const auto knee = [&](Bone b) {
    return w.out.qpos[static_cast<std::size_t>(rig.solved->bodies[sim::index(b)].qpos_adr)];
  };
  CHECK(knee(Bone::LeftLowerLeg) > 0.8);
  CHECK(knee(Bone::RightLowerLeg) > 0.8);
  for (const Bone foot : {Bone::LeftFoot, Bone::RightFoot}) CHECK(std::abs(j[sim::index(foot)].z() - ankle_z) < kMm);
  CHECK(j[0].z() < 0.901 - 0.3);
  CHECK((j[sim::index(Bone::Head)] - bone_target(rig, w.frame, Tracker::head)).norm() < kMm);
}

TEST_CASE("tracker IK: walking forward, the feet step after the pelvis and stand on the floor") {
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  Walker w{rig, {}, {}, {}};
  const double dt = 1.0 / 90.0;  // a headset's rate
  double highest = 0.0;
  int k = 0;
  for (; k * dt <= 3.0; ++k) {
    const double t = k * dt;
    w.at(t, Vec3(std::min(t, 2.0) * 1.0, 0.0, 0.901), 0.0);  // 1 m/s for 2 s, then stand
    const auto j = solved_joints(rig, w.out.qpos);
    highest = std::max(highest, j[sim::index(Bone::LeftFoot)].z() - rig.ik->ankle_height_m);
  }
  const auto j = solved_joints(rig, w.out.qpos);
  CHECK(w.state.stats.steps >= 4);
  CHECK(highest > 0.03);  // a swing lifts the foot
  CHECK(highest < 0.15);
  for (const Bone foot : {Bone::LeftFoot, Bone::RightFoot}) {
    CAPTURE(sim::name(foot));
    CHECK(std::abs(j[sim::index(foot)].z() - rig.ik->ankle_height_m) < kMm);
    CHECK(std::abs(j[sim::index(foot)].x() - 2.0) < 0.15);  // under the pelvis again
  }
}

TEST_CASE("tracker IK: a procedural swing comes down at rest, ahead of the walking pelvis") {
  // A swing aimed at the moving place under the hip lands at the pelvis's
  // speed and stops dead within a frame (the jerk the jitter measures); aimed
  // at where that place will be, it lands at rest, still ahead of the hip.
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  Walker w{rig, {}, {}, {}};
  const double dt = 1.0 / 90.0;
  std::array<double, 2> was_phase{-1.0, -1.0};
  std::array<Vec3, 2> last{Vec3::Zero(), Vec3::Zero()};
  int landings = 0;
  double fastest_landing = 0.0, least_lead = 1.0;
  for (int k = 0; k * dt <= 4.0; ++k) {
    const double t = k * dt;
    w.at(t, Vec3(t * 1.0, 0.0, 0.901), 0.0);  // 1 m/s
    const auto j = solved_joints(rig, w.out.qpos);
    for (std::size_t s = 0; s < 2; ++s) {
      const Vec3 ankle = j[sim::index(s == 0 ? Bone::LeftFoot : Bone::RightFoot)];
      if (t > 1.0 && was_phase[s] >= 0.0 && w.state.foot[s].phase < 0.0) {
        ++landings;
        fastest_landing = std::max(fastest_landing, (ankle - last[s]).norm() / dt);
        least_lead = std::min(least_lead, ankle.x() - w.out.qpos[0]);
      }
      was_phase[s] = w.state.foot[s].phase;
      last[s] = ankle;
    }
  }
  MESSAGE("landings " << landings << ", fastest ankle at touch-down " << fastest_landing << " m/s, least lead "
                      << least_lead << " m");
  CHECK(landings >= 6);
  CHECK(fastest_landing < 0.25);  // the brake sampled at 90 Hz; aimed at the moving place: about 1 m/s
  CHECK(least_lead > 0.05);
}

TEST_CASE("tracker IK: a planted foot pivots under a body spinning faster than it steps") {
  // Two turns in place in 1.5 s: one foot steps at a time, so the other
  // stands while the body turns past it. It keeps its heading for the first
  // foot_pivot_start_rad, then turns about its ankle, the pelvis's lead over
  // it saturating toward start + width (before: the leg twisted up to the
  // ankle's and hip's ranges, which then dragged the foot round).
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  Walker w{rig, {}, {}, {}};
  const IkOptions& o = rig.ik->options;
  const double dt = 1.0 / 90.0;
  const auto yaw_of = [](const Vec3& d) { return std::atan2(d.y(), d.x()); };
  const auto foot_yaw = [&](const std::array<Vec3, sim::kBoneCount>& j, std::size_t s) {
    const std::size_t ankle = sim::index(s == 0 ? Bone::LeftFoot : Bone::RightFoot);
    return yaw_of(j[ankle + 1] - j[ankle]);
  };
  const auto pelvis_yaw = [&](const std::array<Vec3, sim::kBoneCount>& j) {
    const Vec3 left = j[sim::index(Bone::LeftUpperLeg)] - j[sim::index(Bone::RightUpperLeg)];
    return yaw_of(Vec3(left.y(), -left.x(), 0.0));
  };
  w.at(0.0, Vec3(0.0, 0.0, 0.901), 0.0);
  const auto j0 = solved_joints(rig, w.out.qpos);
  // The feet's rest heading against the pelvis's.
  const std::array<double, 2> splay{foot_yaw(j0, 0) - pelvis_yaw(j0), foot_yaw(j0, 1) - pelvis_yaw(j0)};
  double widest = 0.0;
  for (int k = 1; k * dt <= 1.5; ++k) {
    w.at(k * dt, Vec3(0.0, 0.0, 0.901), 4.0 * std::numbers::pi * k * dt / 1.5);
    const auto j = solved_joints(rig, w.out.qpos);
    for (std::size_t s = 0; s < 2; ++s) {
      if (w.state.foot[s].phase >= 0.0) continue;
      const double lead = std::remainder(pelvis_yaw(j) - (foot_yaw(j, s) - splay[s]), 2.0 * std::numbers::pi);
      widest = std::max(widest, std::abs(lead));
    }
  }
  MESSAGE("the spinning pelvis's widest lead over a planted foot " << widest << " rad, " << w.state.stats.steps
                                                                   << " steps");
  CHECK(w.state.stats.steps >= 4);
  CHECK(widest > o.foot_pivot_start_rad);
  CHECK(widest < o.foot_pivot_start_rad + o.foot_pivot_width_rad + 0.02);
}

TEST_CASE("tracker IK: procedural legs reach softly while walking, exactly standing") {
  // The same stream solved with the soft stride and without it: the feet's
  // targets are the same (steps follow the pelvis, not the legs).
  IkRig rig = make_ik_rig(1.70, 3, {}, true);
  IkOptions exact_opt;
  exact_opt.stride_softness_m = 0.0;
  IkRig exact_rig = make_ik_rig(1.70, 3, exact_opt, true);
  Walker w{rig, {}, {}, {}}, e{exact_rig, {}, {}, {}};
  const double dt = 1.0 / 90.0;
  const auto both = [&](double t, const Vec3& root) {
    w.at(t, root, 0.0);
    e.at(t, root, 0.0);
  };
  int k = 0;
  both(0.0, Vec3(0.0, 0.0, 0.901));
  CHECK(w.state.stride_soft_share == 0.0);  // a first frame (a reset) stands straight
  CHECK(w.out.qpos == e.out.qpos);
  double softest = 0.0;
  for (; k * dt <= 1.5; ++k) {
    both(k * dt, Vec3(k * dt * 1.0, 0.0, 0.901));  // 1 m/s
    // Walking, a stance leg never quite straightens (its knee moves smoothly
    // near full extension) and never pushes its foot through the floor.
    const auto j = solved_joints(rig, w.out.qpos);
    for (const Bone shank : {Bone::LeftLowerLeg, Bone::RightLowerLeg}) {
      const auto a = static_cast<std::size_t>(rig.solved->bodies[sim::index(shank)].qpos_adr);
      CHECK(w.out.qpos[a] >= e.out.qpos[a] - 1e-9);
      softest = std::max(softest, w.out.qpos[a] - e.out.qpos[a]);
      CHECK(j[sim::index(shank) + 1].z() > rig.ik->ankle_height_m - kMm);
    }
  }
  CHECK(w.state.stride_soft_share > 0.9);
  CHECK(softest > 0.05);  // rad: the soft knees bend where the exact ones snap straight
  for (const double stop = k * dt; k * dt <= stop + 1.5; ++k) both(k * dt, Vec3(stop, 0.0, 0.901));  // stands
  CHECK(w.state.stride_soft_share < 0.01);
  // Standing, the legs are the exact solver's: the feet (on the floor when
  // in reach) to 0.2 mm. A straight knee moves as the square root of the
  // slack, so the fading softness still shows there: a bend of about 0.013 rad.
  const auto j = solved_joints(rig, w.out.qpos);
  const auto je = solved_joints(exact_rig, e.out.qpos);
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    CAPTURE(sim::kBones[b].name);
    const bool knee = b == sim::index(Bone::LeftLowerLeg) || b == sim::index(Bone::RightLowerLeg);
    CHECK((j[b] - je[b]).norm() < (knee ? 5.0 : 0.2) * kMm);
  }
  for (const Bone shank : {Bone::LeftLowerLeg, Bone::RightLowerLeg}) {
    const auto a = static_cast<std::size_t>(rig.solved->bodies[sim::index(shank)].qpos_adr);
    CHECK(std::abs(w.out.qpos[a] - e.out.qpos[a]) < 0.02);
  }
  // 6 points: tracked feet are reached exactly however fast the pelvis moves.
  IkRig six = make_ik_rig(1.70, 6, {}, true);
  Walker v{six, {}, {}, {}};
  double worst = 0.0;
  for (int i = 0; i * dt <= 1.5; ++i) {
    v.at(i * dt, Vec3(i * dt * 1.0, 0.0, 0.901), 0.0);
    worst = std::max({worst, v.out.foot_error_m[0], v.out.foot_error_m[1]});
  }
  CHECK(worst < kMm);
}

TEST_CASE("tracker IK: bad input is ignored, held, eased, flagged, never a NaN") {
  IkOptions opt;
  opt.hold_s = 0.2;
  opt.ease_s = 0.3;
  IkRig rig = make_ik_rig(1.70, 3, opt, true);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto root = Vec3(0.0, 0.0, 0.901);

  SUBCASE("no head yet: the rest pose, flagged") {
    IkState st;
    IkOutput out;
    TrackerFrame f = pose_truth(rig, rest_qpos(*rig.truth, root, 0.0), 0.0);
    f[Tracker::head].valid = false;
    solve_ik(*rig.ik, st, f, out);
    CHECK((out.flags & kIkNoHead) != 0);
    CHECK(all_finite(out));
  }
  SUBCASE("a NaN or a non-rotation sample is ignored: the frame is what the last good one gave") {
    IkState st;
    IkOutput out;
    const TrackerFrame good = pose_truth(rig, rest_qpos(*rig.truth, root, 0.0), 0.0);
    solve_ik(*rig.ik, st, good, out);
    for (int kind = 0; kind < 3; ++kind) {
      TrackerFrame f = good;
      f.time_s = 0.001 * (kind + 1);
      // What the last good sample gives at this time, from the same state
      // (the poles' smoothing goes on, so not the previous frame's output).
      IkState twin = st;
      IkOutput expected;
      TrackerFrame held = good;
      held.time_s = f.time_s;
      solve_ik(*rig.ik, twin, held, expected);
      if (kind == 0) f[Tracker::head].pos_m.x() = nan;
      if (kind == 1) f[Tracker::left_hand].rot = Quat(0.0, 0.0, 0.0, 0.0);
      if (kind == 2) f[Tracker::right_hand].pos_m = Vec3(1e300, 0.0, 0.0);
      solve_ik(*rig.ik, st, f, out);
      CHECK((out.flags & kIkTrackerInvalid) != 0);
      REQUIRE(all_finite(out));
      for (int i = 0; i < out.nq; ++i) {
        CHECK(out.qpos[static_cast<std::size_t>(i)] ==
              doctest::Approx(expected.qpos[static_cast<std::size_t>(i)]).epsilon(1e-9));
      }
    }
    CHECK(st.stats.invalid_samples == 3);
  }
  SUBCASE("a lost hand is held, eased to hang at the side, and blended back when it returns") {
    IkState st;
    IkOutput out;
    auto q = rest_qpos(*rig.truth, root, 0.0);
    TrackerFrame f = pose_truth(rig, q, 0.0);
    const Vec3 held = bone_target(rig, f, Tracker::left_hand);
    solve_ik(*rig.ik, st, f, out);
    int tick = 0;                // 10 ms each
    for (; tick < 15; ++tick) {  // within the hold time
      f.time_s = 0.01 * (tick + 1);
      f[Tracker::left_hand].valid = false;
      solve_ik(*rig.ik, st, f, out);
    }
    CHECK(out.use[index(Tracker::left_hand)] == TrackerUse::held);
    CHECK((solved_joints(rig, out.qpos)[sim::index(Bone::LeftHand)] - held).norm() < kMm);
    for (; tick < 80; ++tick) {  // past hold + ease
      f.time_s = 0.01 * (tick + 1);
      f[Tracker::left_hand].valid = false;
      solve_ik(*rig.ik, st, f, out);
    }
    CHECK(out.use[index(Tracker::left_hand)] == TrackerUse::neutral);
    CHECK((out.flags & kIkTrackerEased) != 0);
    const auto j = solved_joints(rig, out.qpos);
    // Hanging: the wrist about an arm's length below the shoulder.
    CHECK(j[sim::index(Bone::LeftUpperArm)].z() - j[sim::index(Bone::LeftHand)].z() > 0.45);
    const TrackerFrame back = pose_truth(rig, q, 0.01 * (tick + 1));
    f = back;
    solve_ik(*rig.ik, st, f, out);
    CHECK(out.use[index(Tracker::left_hand)] == TrackerUse::recovering);
    const double first = (solved_joints(rig, out.qpos)[sim::index(Bone::LeftHand)] - held).norm();
    CHECK(first > 0.3);  // no snap back
    for (int k = 0; k < 30; ++k) {
      f.time_s += 0.01;
      solve_ik(*rig.ik, st, f, out);
    }
    CHECK(out.use[index(Tracker::left_hand)] == TrackerUse::live);
    CHECK((solved_joints(rig, out.qpos)[sim::index(Bone::LeftHand)] - held).norm() < kMm);
  }
  SUBCASE("a hand 3 m away is flagged and the arm points at it; swapped hands are flagged") {
    IkState st;
    IkOutput out;
    TrackerFrame f = pose_truth(rig, rest_qpos(*rig.truth, root, 0.0), 0.0);
    f[Tracker::left_hand].pos_m = f[Tracker::head].pos_m + Vec3(0.0, 3.0, 0.0);
    solve_ik(*rig.ik, st, f, out);
    CHECK((out.flags & kIkImplausible) != 0);
    CHECK((out.flags & kIkHandUnreachable) != 0);
    REQUIRE(all_finite(out));
    const auto j = solved_joints(rig, out.qpos);
    const Vec3 arm = (j[sim::index(Bone::LeftHand)] - j[sim::index(Bone::LeftUpperArm)]).normalized();
    const Vec3 want = (f[Tracker::left_hand].pos_m - j[sim::index(Bone::LeftUpperArm)]).normalized();
    CHECK(arm.dot(want) > 0.99);

    TrackerFrame g = pose_truth(rig, rest_qpos(*rig.truth, root, 0.0), 1.0);
    std::swap(g[Tracker::left_hand], g[Tracker::right_hand]);
    IkState st2;
    solve_ik(*rig.ik, st2, g, out);
    CHECK((out.flags & kIkHandsSwapped) != 0);
    CHECK(all_finite(out));
  }
  SUBCASE("time going backwards is flagged, not a negative step") {
    IkState st;
    IkOutput out;
    TrackerFrame f = pose_truth(rig, rest_qpos(*rig.truth, root, 0.0), 5.0);
    solve_ik(*rig.ik, st, f, out);
    f.time_s = 4.0;
    solve_ik(*rig.ik, st, f, out);
    CHECK((out.flags & kIkBadTime) != 0);
    f.time_s = nan;
    solve_ik(*rig.ik, st, f, out);
    CHECK((out.flags & kIkBadTime) != 0);
    CHECK(all_finite(out));
  }
}

TEST_CASE("tracker IK: a model or options that cannot work are refused") {
  IkRig rig = make_ik_rig(1.70, 3);
  IkOptions bad;
  bad.step_time_s = -1.0;
  CHECK_FALSE(make_ik_model(*rig.solved, rig.calibration, bad).model);
  BodyCalibration no_head = rig.calibration;
  no_head.offset[index(Tracker::head)].valid = false;
  CHECK(make_ik_model(*rig.solved, no_head).error.find("head") != std::string::npos);
  sim::Model other = *rig.solved;
  other.bodies[3].parent = 0;
  CHECK_FALSE(make_ik_model(other, rig.calibration).model);
}

}  // namespace
}  // namespace tonus::reference::test
