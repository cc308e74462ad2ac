// The robust filter's arm swing (arm_swing.hpp): each arm turns rigidly about
// its shoulder joint, forward for a positive swing, and nothing else moves;
// the written clip's arms are where the filter put them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "balance_fixtures.hpp"
#include "clip_paths.hpp"
#include "synthetic_body.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/arm_swing.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/filter.hpp"
#include "tonus/host/balance/skeleton_map.hpp"

namespace tonus::balance {
namespace {

using sim::Bone;

struct ArmPoints {
  Bone shoulder, elbow, wrist;
  Landmark tip;
};
constexpr ArmPoints kArm[2] = {{Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand, Landmark::LeftHandTip},
                               {Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand, Landmark::RightHandTip}};

bool arm_landmark(std::size_t l) {
  for (const ArmPoints& a : kArm) {
    if (l == sim::index(a.elbow) || l == sim::index(a.wrist) || l == index(a.tip)) return true;
  }
  return false;
}

MotionFrame standing_frame() {
  // Feet pointing +z in the file: forward is +x in the internal frame.
  const motion::Clip clip =
      test::synthetic_body(3, test::Names::bandai, [](double) { return Eigen::Vector3d::Zero(); });
  ConvertOptions o;
  o.metres_per_unit = 0.01;
  const Conversion c = convert_motion(clip, map_skeleton(clip), o);
  REQUIRE_MESSAGE(c.ok(), c.error);
  return c.motion.frames[1];
}

}  // namespace

TEST_CASE("arm swing: each arm turns rigidly about its shoulder, forward when positive, and nothing else moves") {
  const MotionFrame f = standing_frame();
  const Vec2 swing(0.4, -0.25);
  const MotionFrame s = swing_arms(f, swing);
  for (std::size_t l = 0; l < kLandmarkCount; ++l) {
    if (!arm_landmark(l)) CHECK(s.p[l] == f.p[l]);  // the shoulders included
  }
  const Vec3 across = f.p[sim::index(Bone::RightUpperArm)] - f.p[sim::index(Bone::LeftUpperArm)];
  for (std::size_t side = 0; side < 2; ++side) {
    const ArmPoints& a = kArm[side];
    const double angle = swing(static_cast<Eigen::Index>(side));
    const Vec3 o = f.p[sim::index(a.shoulder)];
    for (const std::size_t l : {sim::index(a.elbow), sim::index(a.wrist), index(a.tip)}) {
      const Vec3 before = f.p[l] - o, after = s.p[l] - o;
      CHECK(after.norm() == doctest::Approx(before.norm()).epsilon(1e-12));  // rigid about the shoulder
      CHECK(std::acos(std::clamp(before.normalized().dot(after.normalized()), -1.0, 1.0)) ==
            doctest::Approx(std::abs(angle)).epsilon(1e-9));
      CHECK(std::abs((after - before).dot(across)) < 1e-12);  // in the plane square to the shoulders' line
    }
    // The hanging arm's hand goes forward (+x) and up for a positive swing.
    const Vec3 moved = s.p[index(a.tip)] - f.p[index(a.tip)];
    CHECK(moved.x() * angle > 0.0);
    CHECK(moved.z() > 0.0);
    for (const Bone b : {a.shoulder, a.elbow, a.wrist})
      CHECK(s.rotation[sim::index(b)].angularDistance(f.rotation[sim::index(b)]) ==
            doctest::Approx(std::abs(angle)).epsilon(1e-9));
  }
  const MotionFrame none = swing_arms(f, Vec2::Zero());
  for (std::size_t l = 0; l < kLandmarkCount; ++l) CHECK(none.p[l] == f.p[l]);
}

TEST_CASE("arm swing: the written clip's arms are where the filter put them") {
  const test::Loaded l = test::load(test::shared_clip("dataset-1_walk_normal_001.bvh"));
  const HumanMotion& m = l.conversion.motion;
  std::vector<Vec2> shift(m.size()), arms(m.size());
  std::vector<Vec3> turn(m.size());
  for (std::size_t t = 0; t < m.size(); ++t) {
    const double s = std::sin(0.1 * static_cast<double>(t));
    shift[t] = Vec2(0.03 * s, -0.02 * s);
    turn[t] = Vec3(0.05 * s, 0.08 * s, 0.1 * s);
    arms[t] = Vec2(0.4 * s, -0.3 * std::cos(0.07 * static_cast<double>(t)));
  }
  const AppliedCorrection applied = apply_correction(l.clip, l.conversion.geometry, m, turn, shift, {}, {}, arms);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  const Conversion back = convert_motion(applied.clip, l.mapping, {});
  REQUIRE_MESSAGE(back.ok(), back.error);
  double apart = 0.0, swung = 0.0;
  for (std::size_t t = m.first_frame; t < m.size(); ++t) {
    const MotionFrame waist = correct_waist(m.frames[t], turn[t], shift[t]);
    const MotionFrame c = swing_arms(waist, arms[t]);
    for (std::size_t p = 0; p < kLandmarkCount; ++p) {
      apart = std::max(apart, (back.motion.frames[t].p[p] - c.p[p]).norm());
      swung = std::max(swung, (c.p[p] - waist.p[p]).norm());
    }
  }
  MESSAGE("every landmark of the written clip from the filter's: at most " << apart << " m (the arms swung by up to "
                                                                           << swung << " m)");
  CHECK(swung > 0.2);
  CHECK(apart < 1e-5);
}

}  // namespace tonus::balance
