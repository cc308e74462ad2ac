// Full-body retargeting of streamed bone rotations (BodyRetarget), checked
// against what does not use it: the humanoid's own forward kinematics (sim),
// a source skeleton's forward kinematics written here, and real clips'
// landmarks (balance), evaluated as the clip retargeting is
// (reference_checks.hpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "clip_stream.hpp"
#include "reference_checks.hpp"
#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/joint_limits.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;
using reference::BodyRetarget;
using reference::BodyRetargetState;
using reference::BodySample;
using reference::BodyStatus;
using reference::SourceSkeleton;
using sim::Bone;
using sim::Quat;
using sim::Vec3;

namespace {

constexpr std::size_t kN = sim::kBoneCount;
constexpr double kDegPerRad = 180.0 / M_PI;

std::size_t bi(Bone b) { return sim::index(b); }
std::size_t parent_of(std::size_t i) { return sim::index(*sim::kBones[i].parent); }

// A small deterministic generator (the standard distributions differ between libraries).
struct Rng {
  std::uint64_t s;
  double uniform() {  // [0, 1)
    s ^= s << 13U;
    s ^= s >> 7U;
    s ^= s << 17U;
    return static_cast<double>(s >> 11U) * 0x1.0p-53;
  }
  double between(double a, double b) { return a + (b - a) * uniform(); }
  Vec3 unit() {
    for (;;) {
      const Vec3 v(between(-1, 1), between(-1, 1), between(-1, 1));
      if (v.norm() > 0.1 && v.norm() <= 1.0) return v.normalized();
    }
  }
  Quat turn(double max_rad) { return Quat(Eigen::AngleAxisd(between(0.0, max_rad), unit())); }
};

double angle_deg(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad; }

BodyRetarget make(const SourceSkeleton& s) {
  reference::BodyRetargetBuild b = BodyRetarget::create(reference::test::humanoid(), s);
  REQUIRE_MESSAGE(b.ok(), b.error);
  return *b.retarget;
}

// The humanoid's lowest foot point (every box corner, capsule end, sphere bottom of the feet and toes).
double lowest_foot_z(const sim::Model& m, const sim::Data& d) {
  double low = std::numeric_limits<double>::infinity();
  for (std::size_t g = 0; g < static_cast<std::size_t>(m.ngeom); ++g) {
    const auto b = static_cast<std::size_t>(m.geoms[g].body);
    if (b != bi(Bone::LeftFoot) && b != bi(Bone::RightFoot) && b != bi(Bone::LeftToes) && b != bi(Bone::RightToes))
      continue;
    const sim::Shape& s = m.geoms[g].shape;
    const sim::Pose& x = d.xgeom[g];
    if (s.type == sim::ShapeType::box) {
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) != 0 ? 1.0 : -1.0, (c & 2) != 0 ? 1.0 : -1.0, (c & 4) != 0 ? 1.0 : -1.0);
        low = std::min(low, x.apply(corner.cwiseProduct(s.half_extents_m)).z());
      }
    } else if (s.type == sim::ShapeType::capsule) {
      for (const double e : {-1.0, 1.0}) low = std::min(low, x.apply(Vec3(0, 0, e * s.half_length_m)).z() - s.radius_m);
    } else if (s.type == sim::ShapeType::sphere) {
      low = std::min(low, x.pos.z() - s.radius_m);
    }
  }
  return low;
}

// A random configuration inside every joint's range.
std::array<double, sim::kMaxQpos> random_qpos(const sim::Model& m, Rng& rng) {
  std::array<double, sim::kMaxQpos> q = m.qpos0;
  for (std::size_t i = 0; i < kN; ++i) {
    const sim::Body& b = m.bodies[i];
    const auto a = static_cast<std::size_t>(b.qpos_adr);
    if (b.joint == sim::JointType::free) {
      q[a] = rng.between(-2, 2);
      q[a + 1] = rng.between(-2, 2);
      q[a + 2] = rng.between(0.6, 1.1);
      const Quat r = rng.turn(M_PI);
      q[a + 3] = r.w(), q[a + 4] = r.x(), q[a + 5] = r.y(), q[a + 6] = r.z();
    } else if (b.joint == sim::JointType::ball) {
      sim::JointLimit inside = b.limit;  // strictly inside, so a re-clamp has nothing to do
      inside.swing_max_rad *= 0.99;
      inside.lower_rad *= 0.99;
      inside.upper_rad *= 0.99;
      Quat r = rng.turn(2.0);
      sim::clamp_ball(inside, r);
      q[a] = r.w(), q[a + 1] = r.x(), q[a + 2] = r.y(), q[a + 3] = r.z();
    } else if (b.joint == sim::JointType::hinge) {
      q[a] = rng.between(0.99 * b.limit.lower_rad, 0.99 * b.limit.upper_rad);
    }
  }
  return q;
}

// The sample a sender with the humanoid's own skeleton would send for the posed `d`.
BodySample sample_of(const sim::Data& d) {
  BodySample s;
  for (std::size_t i = 1; i < kN; ++i) {
    s.present[i] = true;
    s.local[i] = d.xquat[parent_of(i)].conjugate() * d.xquat[i];
  }
  s.root_present = true;
  s.root_position = d.xbody[0].pos;
  s.root_rotation = d.xquat[0];
  return s;
}

using reference::test::source_fk;
using reference::test::source_parent;
using reference::test::SourcePose;
SourcePose source_rest(const SourceSkeleton& s) {
  BodySample rest;
  rest.root_position = s.offset[0];
  rest.root_rotation = s.rest_rotation[0];
  rest.local = s.rest_rotation;
  return source_fk(s, rest);
}

// The same skeleton and motion with every bone's own axes turned by frame[i]
// (as rigs differ in their bone-axis conventions): world rotations W' = W * F.
SourceSkeleton reframed(const SourceSkeleton& s, const std::array<Quat, kN>& frame) {
  SourceSkeleton r = s;
  r.rest_rotation[0] = s.rest_rotation[0] * frame[0];
  for (std::size_t i = 1; i < kN; ++i) {
    if (!s.present[i]) continue;
    const auto p = static_cast<std::size_t>(source_parent(s, i));
    r.rest_rotation[i] = frame[p].conjugate() * s.rest_rotation[i] * frame[i];
    r.offset[i] = frame[p].conjugate() * s.offset[i];
  }
  return r;
}
struct Seg {
  Bone from, to;
};
constexpr Seg kSegs[] = {{Bone::LeftUpperArm, Bone::LeftLowerArm},
                         {Bone::RightUpperArm, Bone::RightLowerArm},
                         {Bone::LeftLowerArm, Bone::LeftHand},
                         {Bone::RightLowerArm, Bone::RightHand},
                         {Bone::LeftUpperLeg, Bone::LeftLowerLeg},
                         {Bone::RightUpperLeg, Bone::RightLowerLeg},
                         {Bone::LeftLowerLeg, Bone::LeftFoot},
                         {Bone::RightLowerLeg, Bone::RightFoot},
                         {Bone::Spine, Bone::Chest},
                         {Bone::Neck, Bone::Head}};

Vec3 mid_hip(const sim::Data& d) {
  return 0.5 * (d.xbody[bi(Bone::LeftUpperLeg)].pos + d.xbody[bi(Bone::RightUpperLeg)].pos);
}

}  // namespace

TEST_CASE("body retarget: the humanoid's own poses come back (round trip through its forward kinematics)") {
  const sim::Model& m = reference::test::humanoid();
  const BodyRetarget rt = make(reference::skeleton_of(m));
  CHECK(rt.scale() == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(std::abs(rt.height_offset_m()) < 1e-12);
  BodyRetargetState state;
  auto truth = sim::make_data(m), ours = sim::make_data(m);
  Rng rng{0x5eed1234ULL};
  double worst_joint = 0.0, worst_dir = 0.0, worst_pos = 0.0;
  int clamped = 0;
  for (int trial = 0; trial < 500; ++trial) {
    truth->qpos = random_qpos(m, rng);
    sim::forward_kinematics(m, *truth);
    const BodyStatus st = rt.solve(sample_of(*truth), state, ours->qpos);
    REQUIRE(st.written);
    CHECK(st.input_valid());
    clamped += st.clamped;
    sim::forward_kinematics(m, *ours);
    for (std::size_t i = 0; i < kN; ++i) {
      const sim::Body& b = m.bodies[i];
      const auto a = static_cast<std::size_t>(b.qpos_adr);
      if (b.joint == sim::JointType::hinge) {
        worst_joint = std::max(worst_joint, std::abs(ours->qpos[a] - truth->qpos[a]));
      } else {
        const std::size_t qa = a + (b.joint == sim::JointType::free ? 3 : 0);
        const Quat x(truth->qpos[qa], truth->qpos[qa + 1], truth->qpos[qa + 2], truth->qpos[qa + 3]);
        const Quat y(ours->qpos[qa], ours->qpos[qa + 1], ours->qpos[qa + 2], ours->qpos[qa + 3]);
        worst_joint = std::max(worst_joint, x.angularDistance(y));
      }
      worst_pos = std::max(worst_pos, (ours->xbody[i].pos - truth->xbody[i].pos).norm());
      if (i > 0) {
        const std::size_t p = parent_of(i);
        const Vec3 t = truth->xbody[i].pos - truth->xbody[p].pos, o = ours->xbody[i].pos - ours->xbody[p].pos;
        worst_dir = std::max(worst_dir, angle_deg(t, o));
      }
    }
  }
  MESSAGE("round trip, 500 random poses within the limits: worst joint error "
          << worst_joint << " (rad or rad of turn), "
          << "worst bone direction " << worst_dir << " deg, worst joint position " << worst_pos << " m");
  CHECK(worst_joint < 1e-9);
  CHECK(worst_dir < 1e-7);
  CHECK(worst_pos < 1e-9);
  CHECK(clamped == 0);
}

TEST_CASE("body retarget: an A-pose source with other bone lengths and bone axes") {
  const sim::Model& m = reference::test::humanoid();
  const SourceSkeleton t_pose = reference::skeleton_of(m);
  const SourceSkeleton a_pose = reference::a_pose_variant(t_pose, 45.0 * M_PI / 180.0, 0.9, 1.1);
  Rng rng{0xa9053ULL};
  std::array<Quat, kN> frame{};
  for (Quat& f : frame) f = rng.turn(M_PI);  // every bone with its own axis convention
  const SourceSkeleton src = reframed(a_pose, frame);
  const BodyRetarget rt = make(src);

  // The scale is the leg ratio: 1 / 1.1 (hip to ankle, both measured here from the offsets).
  const auto leg = [&](const SourceSkeleton& s) {
    return s.offset[bi(Bone::LeftLowerLeg)].norm() + s.offset[bi(Bone::LeftFoot)].norm();
  };
  CHECK(rt.scale() == doctest::Approx(leg(t_pose) / leg(src)).epsilon(1e-12));
  CHECK(rt.scale() == doctest::Approx(1.0 / 1.1).epsilon(1e-12));

  // The source's rest: the humanoid's arms hang 45 degrees, its feet stand on z = 0.
  auto d = sim::make_data(m);
  BodyRetargetState state;
  BodySample rest;
  rest.present = src.present;
  rest.local = src.rest_rotation;
  rest.root_present = true;
  rest.root_position = src.offset[0];
  rest.root_rotation = src.rest_rotation[0];
  REQUIRE(rt.solve(rest, state, d->qpos).written);
  sim::forward_kinematics(m, *d);
  const Vec3 arm = d->xbody[bi(Bone::LeftLowerArm)].pos - d->xbody[bi(Bone::LeftUpperArm)].pos;
  CHECK(angle_deg(arm, Vec3(0, 1, -1)) < 1e-9);
  CHECK(std::abs(lowest_foot_z(m, *d)) < 1e-9);
  MESSAGE("A-pose rest: lowest foot point " << lowest_foot_z(m, *d) << " m");
  const Vec3 rest_mid_hip = mid_hip(*d);
  const Vec3 src_rest_mid = [&] {
    const SourcePose p = source_fk(src, rest);
    return Vec3(0.5 * (p.pos[bi(Bone::LeftUpperLeg)] + p.pos[bi(Bone::RightUpperLeg)]));
  }();

  // Poses: every joint turned in the source's rest frame, elbows and knees
  // about their own hinge axes; the segments' directions from the source's FK.
  const Quat arm_down_left(Eigen::AngleAxisd(-M_PI / 4, Vec3::UnitX()));
  const Quat arm_down_right(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()));
  const SourcePose src_rest = source_rest(src);
  std::vector<double> errors;
  double worst_root = 0.0, worst_standing_foot = 0.0;
  int clamped = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const bool standing = trial % 3 == 0;  // legs, trunk and root at rest, feet flat
    std::array<Quat, kN> turn{};           // D_i, the bone's world turn from its rest
    turn[0] =
        standing ? Quat::Identity() : Quat(Eigen::AngleAxisd(rng.between(-M_PI, M_PI), Vec3::UnitZ())) * rng.turn(0.2);
    for (std::size_t i = 1; i < kN; ++i) {
      const Bone b = sim::kBones[i].bone;
      const Quat& up = turn[parent_of(i)];
      const bool leg_or_trunk = i >= bi(Bone::LeftUpperLeg) || i <= bi(Bone::Head);
      Quat joint = rng.turn(0.25);
      switch (b) {
        case Bone::LeftUpperArm:
        case Bone::RightUpperArm: joint = rng.turn(0.7); break;
        case Bone::LeftUpperLeg:
        case Bone::RightUpperLeg: joint = rng.turn(0.5); break;
        case Bone::LeftLowerArm:
          joint = Quat(Eigen::AngleAxisd(rng.between(0.05, 2.0), arm_down_left * -Vec3::UnitZ()));
          break;
        case Bone::RightLowerArm:
          joint = Quat(Eigen::AngleAxisd(rng.between(0.05, 2.0), arm_down_right * Vec3::UnitZ()));
          break;
        case Bone::LeftLowerLeg:
        case Bone::RightLowerLeg: joint = Quat(Eigen::AngleAxisd(rng.between(0.05, 2.0), Vec3::UnitY())); break;
        case Bone::LeftToes:
        case Bone::RightToes: joint = Quat(Eigen::AngleAxisd(rng.between(-0.5, 0.3), Vec3::UnitY())); break;
        default: break;
      }
      if (standing && leg_or_trunk) joint = Quat::Identity();
      turn[i] = up * joint;
    }
    BodySample in;
    in.present = src.present;
    in.root_present = true;
    in.root_position =
        src.offset[0] + (standing ? Vec3(rng.between(-1, 1), rng.between(-1, 1), 0.0)
                                  : Vec3(rng.between(-1, 1), rng.between(-1, 1), rng.between(-0.3, 0.1)));
    in.root_rotation = turn[0] * src_rest.world[0];
    for (std::size_t i = 1; i < kN; ++i) {
      const Quat w = turn[i] * src_rest.world[i];
      in.local[i] = (turn[static_cast<std::size_t>(source_parent(src, i))] *
                     src_rest.world[static_cast<std::size_t>(source_parent(src, i))])
                        .conjugate() *
                    w;
    }
    const SourcePose sp = source_fk(src, in);
    const BodyStatus st = rt.solve(in, state, d->qpos);
    REQUIRE(st.written);
    clamped += st.clamped;
    sim::forward_kinematics(m, *d);
    for (const Seg& s : kSegs) {
      const Vec3 ours = d->xbody[bi(s.to)].pos - d->xbody[bi(s.from)].pos;
      errors.push_back(angle_deg(ours, sp.pos[bi(s.to)] - sp.pos[bi(s.from)]));
    }
    // The root: the mid-hip moves by the source's mid-hip displacement, scaled.
    const Vec3 src_mid = 0.5 * (sp.pos[bi(Bone::LeftUpperLeg)] + sp.pos[bi(Bone::RightUpperLeg)]);
    worst_root = std::max(worst_root, (mid_hip(*d) - rest_mid_hip - rt.scale() * (src_mid - src_rest_mid)).norm());
    if (standing) worst_standing_foot = std::max(worst_standing_foot, std::abs(lowest_foot_z(m, *d)));
  }
  const reference::test::Spread e = reference::test::spread(errors);
  MESSAGE("A-pose source (arms 0.9x, legs 1.1x, own bone axes), 300 poses: segment direction error median "
          << e.median << ", p95 " << e.p95 << ", max " << e.max << " deg; root error " << worst_root
          << " m; standing feet |z| max " << worst_standing_foot << " m; joints clamped " << clamped);
  CHECK(e.max < 1e-6);
  CHECK(worst_root < 1e-9);
  CHECK(worst_standing_foot < 1e-9);
  CHECK(clamped == 0);
}

namespace {

struct ClipRun {
  reference::test::Figures fig;
  double scale = 0.0;
  std::size_t frames_clamped = 0;
  std::array<std::size_t, kN> clamped_per_bone{};
  double seconds_per_frame = 0.0;
};

// A BVH clip as a sender would stream it: its mapped bones' local rotations
// (relative to the nearest mapped ancestor, Z up), the Hips' pose, and its
// own rest pose (OFFSETs, zero rotations) as the source skeleton.
ClipRun run_clip(const std::string& name, const std::string& path) {
  const sim::Model& m = reference::test::humanoid();
  const reference::test::ClipStream stream = reference::test::stream_clip(path);
  const SourceSkeleton& src = stream.skeleton;
  const balance::HumanMotion& motion = stream.conv.motion;
  const BodyRetarget rt = make(src);

  reference::ClipReference ref;
  ref.nq = m.nq;
  ref.scale = rt.scale();
  ref.qpos.assign(motion.size(), m.qpos0);
  BodyRetargetState state;
  ClipRun run;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t f = 0; f < motion.size(); ++f) {
    const BodyStatus st = rt.solve(stream.samples[f], state, ref.qpos[f]);
    REQUIRE(st.written);
    CHECK(st.input_valid());
    CHECK_FALSE(st.fallback);
    if (st.clamped > 0 && f >= motion.first_frame) ++run.frames_clamped;
    for (std::size_t i = 0; i < kN; ++i) {
      if (f >= motion.first_frame && (st.clamped_bones >> i & 1U) != 0) ++run.clamped_per_bone[i];
    }
  }
  run.seconds_per_frame =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / static_cast<double>(motion.size());
  run.fig = reference::test::evaluate(m, motion, ref);
  run.scale = rt.scale();
  const reference::test::Figures& fig = run.fig;
  std::string seg = "\n  clamped:";
  for (std::size_t i = 0; i < kN; ++i) {
    if (run.clamped_per_bone[i] == 0) continue;
    seg += ' ';
    seg += sim::kBones[i].name;
    seg += ' ';
    seg += std::to_string(run.clamped_per_bone[i]);
  }
  for (std::size_t k = 0; k < reference::test::kSegmentKinds; ++k) {
    const reference::test::Spread& s = fig.segment_deg[k];
    seg += std::string("\n  ") + reference::test::kSegmentNames[k] + ": median " + std::to_string(s.median) + ", p95 " +
           std::to_string(s.p95) + ", max " + std::to_string(s.max) + " deg";
  }
  MESSAGE(name << " streamed through BodyRetarget (" << motion.size() - motion.first_frame << " frames, scale "
               << rt.scale() << "): direction error median " << fig.all_deg.median << ", p95 " << fig.all_deg.p95
               << ", max " << fig.all_deg.max << " deg" << seg << "\n  feet in contact |z|: median "
               << fig.contact_foot_z_m.median << ", p95 " << fig.contact_foot_z_m.p95 << ", max "
               << fig.contact_foot_z_m.max << " m (" << fig.contact_foot_z_m.n << ")\n  frames clamped "
               << run.frames_clamped << "; largest joint step " << fig.max_step_deg << " deg; sign flips "
               << fig.sign_flips << "; root path error " << fig.root_path_error_m << " m; "
               << run.seconds_per_frame * 1e6 << " us per frame");
  CHECK(fig.max_quat_norm_error < 1e-9);
  CHECK(fig.sign_flips == 0);
  CHECK_MESSAGE(fig.limit_violations == 0, fig.worst_violation);
  return run;
}

}  // namespace

// CMU's rest is a T-pose (legs spread 20 degrees): limbs and spine follow to
// rounding, the neck by 2 to 4 degrees (its unmapped Neck1 joint bends the
// segment), the feet stand within centimetres (its floor climbs 4 cm over the take).
TEST_CASE("body retarget: CMU walk streamed frame by frame (bundled)") {
  const ClipRun r = run_clip("cmu_02_walk", reference::test::bundled_clip("cmu_02_walk.bvh"));
  for (std::size_t k = 0; k < 5; ++k) CHECK(r.fig.segment_deg[k].max < 0.1);
  CHECK(r.fig.segment_deg[5].max < 5.0);
  CHECK(r.fig.contact_foot_z_m.median < 0.015);
  CHECK(r.fig.contact_foot_z_m.p95 < 0.05);
  CHECK(r.fig.contact_foot_z_m.max < 0.07);
  CHECK(r.frames_clamped == 0);
  CHECK(r.fig.max_step_deg < 10.0);
  CHECK(r.fig.root_path_error_m < 1e-9);
}

// Bandai Namco's rest is no human pose (every bone along its own +X: spine
// level, legs sideways), so a bone's rest says nothing of its twist: the
// directions still follow (limits aside), but twists are arbitrary, joints
// clamp and the feet roll. A streaming source needs a human rest (T or A).
TEST_CASE("body retarget: Bandai Namco walk streamed frame by frame (its own rest is no human pose)") {
  const ClipRun r = run_clip("dataset-1_walk", reference::test::shared_clip("dataset-1_walk_normal_001.bvh"));
  CHECK(r.fig.all_deg.median < 0.01);
  CHECK(r.fig.all_deg.p95 < 10.0);
  CHECK(r.fig.all_deg.max < 15.0);
  CHECK(r.fig.segment_deg[4].max < 0.01);
  CHECK(r.fig.segment_deg[5].max < 0.01);
  CHECK(r.fig.root_path_error_m < 1e-6);
}

TEST_CASE("body retarget: bad input never crashes nor gives a non-finite value, and is flagged") {
  const sim::Model& m = reference::test::humanoid();
  const SourceSkeleton src = reference::skeleton_of(m);
  const BodyRetarget rt = make(src);
  auto d = sim::make_data(m);
  Rng rng{0xbad1ULL};
  d->qpos = random_qpos(m, rng);
  sim::forward_kinematics(m, *d);
  const BodySample good = sample_of(*d);
  BodyRetargetState state;
  std::array<double, sim::kMaxQpos> out{}, first{};
  REQUIRE(rt.solve(good, state, first).written);
  const auto finite = [&](const std::array<double, sim::kMaxQpos>& q) {
    return std::all_of(q.begin(), q.begin() + m.nq, [](double x) { return std::isfinite(x); });
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::size_t elbow = bi(Bone::LeftLowerArm), hand = bi(Bone::RightHand);

  // A NaN and a zero quaternion: flagged, the last valid kept, so the output does not move.
  BodySample bad = good;
  bad.local[elbow] = Quat(nan, 0, 0, 0);
  bad.local[hand] = Quat(0, 0, 0, 0);
  BodyStatus st = rt.solve(bad, state, out);
  CHECK(st.written);
  CHECK(st.invalid_bones == ((1U << elbow) | (1U << hand)));
  CHECK_FALSE(st.input_valid());
  CHECK(finite(out));
  for (int k = 0; k < m.nq; ++k)
    CHECK(out[static_cast<std::size_t>(k)] == doctest::Approx(first[static_cast<std::size_t>(k)]).epsilon(1e-12));
  // Non-unit (norm 2): refused too.
  bad = good;
  bad.local[elbow].coeffs() *= 2.0;
  CHECK(rt.solve(bad, state, out).invalid_bones == (1U << elbow));

  // Missing bones: flagged, kept; with missing_keeps_last off, back to rest.
  BodySample missing = good;
  missing.present.fill(false);
  missing.root_present = false;
  st = rt.solve(missing, state, out);
  CHECK(st.missing_bones == ((1U << kN) - 2U));
  CHECK(st.root_missing);
  CHECK(st.input_valid());
  CHECK(finite(out));
  for (int k = 0; k < m.nq; ++k)
    CHECK(out[static_cast<std::size_t>(k)] == doctest::Approx(first[static_cast<std::size_t>(k)]).epsilon(1e-12));
  reference::BodyRetargetOptions to_rest;
  to_rest.missing_keeps_last = false;
  const reference::BodyRetargetBuild rest_build = BodyRetarget::create(m, src, to_rest);
  REQUIRE(rest_build.ok());
  BodyRetargetState rest_state;
  CHECK(rest_build.retarget->solve(good, rest_state, out).written);
  CHECK(rest_build.retarget->solve(missing, rest_state, out).written);
  for (int k = 0; k < m.nq; ++k)
    CHECK(out[static_cast<std::size_t>(k)] == doctest::Approx(m.qpos0[static_cast<std::size_t>(k)]).epsilon(1e-12));

  // An absurd or non-finite root: flagged, the last valid kept.
  for (const Vec3& p : {Vec3(1e12, 0, 0), Vec3(nan, 0, 1), Vec3(0, inf, 0)}) {
    BodySample r = good;
    r.root_position = p;
    r.root_rotation = Quat(inf, 1, 0, 0);
    st = rt.solve(r, state, out);
    CHECK(st.root_position_invalid);
    CHECK(st.root_rotation_invalid);
    CHECK(finite(out));
    for (std::size_t k = 0; k < 7; ++k) CHECK(out[k] == doctest::Approx(first[k]).epsilon(1e-12));
  }

  // Too short an output: nothing written.
  std::array<double, 5> tiny{};
  CHECK_FALSE(rt.solve(good, state, tiny).written);

  // Garbage of every kind, 2000 frames: always finite, always within the limits.
  BodyRetargetState garbage_state;
  const double values[] = {nan, inf, -inf, 0.0, 1.0, -1.0, 1e300, -1e-300, 0.5, 1e6};
  const auto pick = [&] {
    return rng.uniform() < 0.5 ? values[static_cast<std::size_t>(rng.uniform() * 10.0)] : rng.between(-2, 2);
  };
  std::size_t not_finite = 0, outside = 0;
  for (int f = 0; f < 2000; ++f) {
    BodySample g;
    for (std::size_t i = 0; i < kN; ++i) {
      g.present[i] = rng.uniform() < 0.8;
      g.local[i] = rng.uniform() < 0.5 ? rng.turn(M_PI) : Quat(pick(), pick(), pick(), pick());
    }
    g.root_present = rng.uniform() < 0.9;
    g.root_position = Vec3(pick(), pick(), pick());
    g.root_rotation = rng.uniform() < 0.5 ? rng.turn(M_PI) : Quat(pick(), pick(), pick(), pick());
    CHECK(rt.solve(g, garbage_state, out).written);
    if (!finite(out)) ++not_finite;
    std::array<double, sim::kMaxQpos> clamped = out;  // a joint outside its range would move (by a turn, not a sign)
    sim::clamp_to_limits(m, clamped);
    for (std::size_t i = 1; i < kN; ++i) {
      const auto q0 = static_cast<std::size_t>(m.bodies[i].qpos_adr);
      const bool hinge = m.bodies[i].joint == sim::JointType::hinge;
      const double moved = hinge ? std::abs(clamped[q0] - out[q0])
                                 : Quat(clamped[q0], clamped[q0 + 1], clamped[q0 + 2], clamped[q0 + 3])
                                       .angularDistance(Quat(out[q0], out[q0 + 1], out[q0 + 2], out[q0 + 3]));
      if (moved > 1e-9) ++outside;
    }
  }
  CHECK(not_finite == 0);
  CHECK(outside == 0);

  // Set-up errors: a required bone missing, a non-finite offset, a zero rest rotation.
  SourceSkeleton no_hand = src;
  no_hand.present[bi(Bone::LeftHand)] = false;
  const reference::BodyRetargetBuild e1 = BodyRetarget::create(m, no_hand);
  CHECK_FALSE(e1.ok());
  CHECK(e1.error.find("LeftHand") != std::string::npos);
  SourceSkeleton nan_offset = src;
  nan_offset.offset[bi(Bone::Spine)].x() = nan;
  CHECK_FALSE(BodyRetarget::create(m, nan_offset).ok());
  SourceSkeleton zero_rot = src;
  zero_rot.rest_rotation[bi(Bone::Chest)] = Quat(0, 0, 0, 0);
  CHECK_FALSE(BodyRetarget::create(m, zero_rot).ok());
}

TEST_CASE("body retarget: deterministic, and continuous through whole turns") {
  const sim::Model& m = reference::test::humanoid();
  const BodyRetarget rt = make(reference::a_pose_variant(reference::skeleton_of(m), 0.6, 1.0, 1.0));
  // Two full turns of the body and the arms waving over the head and back, 1000 frames.
  const auto frame = [](int f) {
    const double t = f / 1000.0;
    BodySample s;
    s.present.fill(true);
    s.root_present = true;
    s.root_position = Vec3(std::cos(2 * M_PI * t), std::sin(2 * M_PI * t), 0.9);
    s.root_rotation = Quat(Eigen::AngleAxisd(4 * M_PI * t, Vec3::UnitZ()));
    s.local[bi(Bone::LeftUpperArm)] = Quat(Eigen::AngleAxisd(2.5 * std::sin(6 * M_PI * t), Vec3::UnitX()));
    s.local[bi(Bone::RightUpperArm)] = Quat(Eigen::AngleAxisd(-2.5 * std::sin(6 * M_PI * t), Vec3::UnitX()));
    s.local[bi(Bone::LeftLowerArm)] = Quat(Eigen::AngleAxisd(1.2 + std::sin(20 * M_PI * t), -Vec3::UnitZ()));
    s.local[bi(Bone::Spine)] = Quat(Eigen::AngleAxisd(0.4 * std::sin(8 * M_PI * t), Vec3::UnitZ()));
    return s;
  };
  BodyRetargetState a, b;
  std::array<double, sim::kMaxQpos> qa{}, qb{}, prev{};
  std::size_t flips = 0, differences = 0;
  double max_step = 0.0;
  for (int f = 0; f < 1000; ++f) {
    rt.solve(frame(f), a, qa);
    rt.solve(frame(f), b, qb);
    for (int k = 0; k < m.nq; ++k)
      differences += qa[static_cast<std::size_t>(k)] == qb[static_cast<std::size_t>(k)] ? 0U : 1U;
    for (std::size_t i = 0; i < kN && f > 0; ++i) {
      const sim::Body& body = m.bodies[i];
      if (body.joint == sim::JointType::hinge) continue;
      const std::size_t q0 = static_cast<std::size_t>(body.qpos_adr) + (body.joint == sim::JointType::free ? 3 : 0);
      const Quat x(qa[q0], qa[q0 + 1], qa[q0 + 2], qa[q0 + 3]), y(prev[q0], prev[q0 + 1], prev[q0 + 2], prev[q0 + 3]);
      if (x.coeffs().dot(y.coeffs()) < 0.0) ++flips;
      max_step = std::max(max_step, x.angularDistance(y) * kDegPerRad);
    }
    prev = qa;
  }
  MESSAGE("1000 frames of whole turns: sign flips " << flips << ", largest joint step " << max_step << " deg");
  CHECK(differences == 0);
  CHECK(flips == 0);
  CHECK(max_step < 5.0);
}
