// Forward kinematics against closed forms worked out by hand: one joint
// turned 90 degrees about each axis and in each channel order, position
// channels replacing the OFFSET, a two-joint chain; then the local rotation
// accessors and writing rotations and translations back.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "bvh_samples.hpp"
#include "support/allocation_counter.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/motion/kinematics.hpp"

using namespace tonus::motion;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A root at the origin with the given channels and an End Site at `tip`,
// one frame with `values`.
Clip one_joint(const std::string& channels, const std::string& values, const std::string& tip) {
  const int count = channels.empty() ? 0 : static_cast<int>(std::count(channels.begin(), channels.end(), ' ')) + 1;
  const std::string text = "HIERARCHY\nROOT A\n{\nOFFSET 0 0 0\nCHANNELS " + std::to_string(count) + " " + channels +
                           "\nEnd Site\n{\nOFFSET " + tip + "\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\n" + values +
                           "\n";
  ReadResult r = parse_bvh(text);
  REQUIRE_MESSAGE(r.ok(), r.error->message);
  return r.clip;
}

Eigen::Vector3d tip_of(const Clip& clip) {
  const std::vector<JointPose> poses = forward_kinematics(clip, 0);
  REQUIRE(poses.size() == 2);
  return poses[1].position;
}

bool near(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm() < 1e-12; }

}  // namespace

TEST_CASE("fk: 90 degrees about one axis (right-handed)") {
  CHECK(near(tip_of(one_joint("Zrotation", "90", "1 0 0")), {0, 1, 0}));
  CHECK(near(tip_of(one_joint("Xrotation", "90", "0 1 0")), {0, 0, 1}));
  CHECK(near(tip_of(one_joint("Yrotation", "90", "0 0 1")), {1, 0, 0}));
  CHECK(near(tip_of(one_joint("Zrotation", "-90", "1 0 0")), {0, -1, 0}));
  CHECK(near(tip_of(one_joint("Yrotation", "180", "1 2 3")), {-1, 2, -3}));
}

TEST_CASE("fk: the channel order is the order of the product, first channel outermost") {
  // Rz(90) Rx(90) y: Rx takes y to z, Rz keeps z.   Rx(90) Rz(90) y: Rz takes y to -x, Rx keeps -x.
  CHECK(near(tip_of(one_joint("Zrotation Xrotation", "90 90", "0 1 0")), {0, 0, 1}));
  CHECK(near(tip_of(one_joint("Xrotation Zrotation", "90 90", "0 1 0")), {-1, 0, 0}));
  // Three 90-degree turns applied to x, innermost (last channel) first:
  // ZYX: Rx: x -> x, Ry: x -> -z, Rz: -z -> -z.
  CHECK(near(tip_of(one_joint("Zrotation Yrotation Xrotation", "90 90 90", "1 0 0")), {0, 0, -1}));
  // XYZ: Rz: x -> y, Ry: y -> y, Rx: y -> z.
  CHECK(near(tip_of(one_joint("Xrotation Yrotation Zrotation", "90 90 90", "1 0 0")), {0, 0, 1}));
  // ZXY (Bandai): Ry: x -> -z, Rx: -z -> y, Rz: y -> -x.
  CHECK(near(tip_of(one_joint("Zrotation Xrotation Yrotation", "90 90 90", "1 0 0")), {-1, 0, 0}));
  // YXZ: Rz: x -> y, Rx: y -> z, Ry: z -> x.
  CHECK(near(tip_of(one_joint("Yrotation Xrotation Zrotation", "90 90 90", "1 0 0")), {1, 0, 0}));
  // YZX: Rx: x -> x, Rz: x -> y, Ry: y -> y.
  CHECK(near(tip_of(one_joint("Yrotation Zrotation Xrotation", "90 90 90", "1 0 0")), {0, 1, 0}));
  // XZY: Ry: x -> -z, Rz: -z -> -z, Rx: -z -> y.
  CHECK(near(tip_of(one_joint("Xrotation Zrotation Yrotation", "90 90 90", "1 0 0")), {0, 1, 0}));
}

TEST_CASE("fk: position channels replace the OFFSET component by component, rotations do not move the joint") {
  const char* text =
      "HIERARCHY\nROOT R\n{\nOFFSET 5 5 5\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      "JOINT C\n{\nOFFSET 7 8 9\nCHANNELS 2 Yposition Xrotation\n"
      "End Site\n{\nOFFSET 0 0 1\n}\n}\n}\nMOTION\nFrames: 2\nFrame Time: 0.01\n"
      "1 2 3 0 0 0 -4 0\n1 2 3 90 0 0 -4 90\n";
  const ReadResult r = parse_bvh(text);
  REQUIRE(r.ok());
  std::vector<JointPose> p;
  REQUIRE(forward_kinematics(r.clip, 0, p));
  REQUIRE(p.size() == 3);
  CHECK(near(p[0].position, {1, 2, 3}));    // the root's OFFSET (5, 5, 5) is replaced, not added
  CHECK(near(p[1].position, {8, -2, 12}));  // x and z from the OFFSET, y from the channel
  CHECK(near(p[1].local_translation, {7, -4, 9}));
  CHECK(near(p[2].position, {8, -2, 13}));
  REQUIRE(forward_kinematics(r.clip, 1, p));
  // Frame 1: root Rz(90) maps (7, -4, 9) to (4, 7, 9); C's Rx(90) maps the tip
  // (0, 0, 1) to (0, -1, 0), then Rz(90) to (1, 0, 0).
  CHECK(near(p[0].position, {1, 2, 3}));
  CHECK(near(p[1].position, {5, 9, 12}));
  CHECK(near(p[2].position, {6, 9, 12}));
  CHECK(p[2].rotation.isApprox(p[1].rotation));  // an End Site has its parent's rotation
  CHECK(p[1].local_rotation.isApprox(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX()))));
}

TEST_CASE("fk: a chain composes global rotations parent first") {
  // Root Ry(90), child Rz(90) at (0, 2, 0), tip at (1, 0, 0):
  // child position: Ry(90) (0, 2, 0) = (0, 2, 0); tip: Ry(90) Rz(90) x = Ry(90) y = y, so (0, 3, 0).
  const char* text =
      "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 1 Yrotation\nJOINT C\n{\nOFFSET 0 2 0\nCHANNELS 1 Zrotation\n"
      "End Site\n{\nOFFSET 1 0 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.01\n90 90\n";
  const ReadResult r = parse_bvh(text);
  REQUIRE(r.ok());
  const std::vector<JointPose> p = forward_kinematics(r.clip, 0);
  REQUIRE(p.size() == 3);
  CHECK(near(p[1].position, {0, 2, 0}));
  CHECK(near(p[2].position, {0, 3, 0}));
  // The child's global rotation: Ry(90) Rz(90) y = Ry(90) (-x) = z.
  CHECK(near(p[1].rotation * Eigen::Vector3d::UnitY(), {0, 0, 1}));
}

TEST_CASE("fk: local accessors agree with the full pass and with the joint's Euler order") {
  const Clip clip = tonus::test::synthetic_clip(4, 21);
  std::vector<JointPose> poses;
  for (std::size_t f = 0; f < clip.frame_count; ++f) {
    REQUIRE(forward_kinematics(clip, f, poses));
    for (std::size_t j = 0; j < clip.joints.size(); ++j) {
      CHECK(local_rotation(clip, f, j)->isApprox(poses[j].local_rotation, 1e-14));
      CHECK(near(*local_translation(clip, f, j), poses[j].local_translation));
    }
    // The arm's channels are X Z Y rotations, columns 6..8.
    const std::span<const double> row = clip.frame(f);
    const Eigen::Quaterniond expected = quaternion_from_euler(EulerOrder::xzy, {row[6], row[7], row[8]});
    CHECK(poses[1].local_rotation.isApprox(expected, 1e-14));
    // The root's rotations are Y Z X (columns 0, 2, 4), its positions X Y Z (1, 3, 5).
    CHECK(poses[0].local_rotation.isApprox(quaternion_from_euler(EulerOrder::yzx, {row[0], row[2], row[4]}), 1e-14));
    CHECK(near(poses[0].position, {row[1], row[3], row[5]}));
  }
  CHECK(rotation_order(clip.joints[0]) == std::optional<EulerOrder>(EulerOrder::yzx));
  CHECK(rotation_order(clip.joints[1]) == std::optional<EulerOrder>(EulerOrder::xzy));
  CHECK_FALSE(rotation_order(clip.joints[2]).has_value());
  Joint two;
  two.channels = {Channel::x_rotation, Channel::y_rotation};
  CHECK_FALSE(rotation_order(two).has_value());
}

TEST_CASE("fk: writing a rotation back into the joint's own channels") {
  Clip clip = tonus::test::synthetic_clip(3, 22);
  const Eigen::Quaterniond q = quaternion_from_euler(EulerOrder::zyx, {10, -20, 30});
  for (std::size_t j = 0; j < 2; ++j) {
    REQUIRE(set_local_rotation(clip, 1, j, q));
    CHECK(local_rotation(clip, 1, j)->isApprox(q, 1e-14));
  }
  // The angles written are those nearest the ones that were there.
  const double before = clip.frame(2)[6];
  const Eigen::Quaterniond same = *local_rotation(clip, 2, 1);
  REQUIRE(set_local_rotation(clip, 2, 1, same));
  CHECK(clip.frame(2)[6] == doctest::Approx(before).epsilon(1e-10));
  // Refused: End Site, out of range, zero or NaN quaternion; nothing changes.
  const std::vector<double> values = clip.values;
  CHECK_FALSE(set_local_rotation(clip, 0, 2, q));
  CHECK_FALSE(set_local_rotation(clip, 3, 1, q));
  CHECK_FALSE(set_local_rotation(clip, 0, 3, q));
  CHECK_FALSE(set_local_rotation(clip, 0, 1, Eigen::Quaterniond(0, 0, 0, 0)));
  CHECK_FALSE(set_local_rotation(clip, 0, 1, Eigen::Quaterniond(kNaN, 0, 0, 1)));
  CHECK(clip.values == values);
}

TEST_CASE("fk: unwrapping a joint's angles changes no rotation and removes representation jumps") {
  using Q = Eigen::Quaterniond;
  const auto about = [](double degrees, int axis) {
    return Q(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::Unit(axis)));
  };
  // The arm's order is xzy: through the +-180 wrap of its first angle, through
  // gimbal lock (middle angle 90) and passing 3 degrees from it.
  for (int path = 0; path < 3; ++path) {
    CAPTURE(path);
    constexpr std::size_t kFrames = 40;
    Clip clip = tonus::test::synthetic_clip(kFrames, 26);
    for (std::size_t f = 0; f < kFrames; ++f) {
      const double t = static_cast<double>(f);
      const Q q = path == 0   ? about(160.0 + t, 0) * about(20, 2) * about(5, 1)
                  : path == 1 ? about(70.0 + t, 2) * about(10, 1)
                              : about(3, 1) * about(70.0 + t, 2) * about(10, 1);
      const EulerAngles principal = euler_from_quaternion(q, EulerOrder::xzy);
      for (std::size_t i = 0; i < 3; ++i) clip.frame(f)[6 + i] = principal.at(i);
    }
    const Clip before = clip;
    // Frames whose arm angles move by more than `degrees` from the previous frame's.
    const auto jumps = [](const Clip& c, double degrees = 90.0) {
      std::vector<std::size_t> at;
      for (std::size_t f = 1; f < c.frame_count; ++f) {
        for (std::size_t i = 6; i < 9; ++i) {
          if (std::abs(c.frame(f)[i] - c.frame(f - 1)[i]) > degrees) {
            at.push_back(f);
            break;
          }
        }
      }
      return at;
    };
    REQUIRE(!jumps(before).empty());
    // Until the input's angles first leap (the path moves a degree a frame)
    // they were already the nearest, so they must be kept exactly.
    const std::vector<std::size_t> leaps = jumps(before, 20.0);
    const std::size_t kept_until = leaps.empty() ? kFrames : leaps.front();
    REQUIRE(unwrap_rotation(clip, 1, 0));
    CHECK(jumps(clip).empty());
    for (std::size_t f = 0; f < kFrames; ++f) {
      CHECK(local_rotation(clip, f, 1)->angularDistance(*local_rotation(before, f, 1)) < 1e-12);
      for (std::size_t i = 0; i < 6; ++i) CHECK(clip.frame(f)[i] == before.frame(f)[i]);  // the root's untouched
      if (f < kept_until) {
        for (std::size_t i = 6; i < 9; ++i) CHECK(clip.frame(f)[i] == before.frame(f)[i]);
      }
    }
  }
  Clip clip = tonus::test::synthetic_clip(3, 27);
  const std::vector<double> values = clip.values;
  CHECK_FALSE(unwrap_rotation(clip, 2, 0));  // an End Site
  CHECK_FALSE(unwrap_rotation(clip, 3, 0));
  CHECK_FALSE(unwrap_rotation(clip, 1, 3));
  CHECK(clip.values == values);
}

TEST_CASE("fk: writing a translation into the position channels") {
  Clip clip = tonus::test::synthetic_clip(2, 23);
  REQUIRE(set_local_translation(clip, 1, 0, {1.5, -2.5, 3.5}));
  CHECK(near(forward_kinematics(clip, 1)[0].position, {1.5, -2.5, 3.5}));
  CHECK(clip.frame(1)[1] == 1.5);  // Xposition is the root's second channel
  CHECK(clip.frame(1)[3] == -2.5);
  CHECK(clip.frame(1)[5] == 3.5);
  CHECK_FALSE(set_local_translation(clip, 1, 1, {0, 0, 0}));  // the arm has no position channels
  CHECK_FALSE(set_local_translation(clip, 2, 0, {0, 0, 0}));
  CHECK_FALSE(set_local_translation(clip, 1, 0, {kNaN, 0, 0}));
}

TEST_CASE("fk: refuses frames without values and malformed hierarchies") {
  Clip clip = tonus::test::synthetic_clip(2, 24);
  std::vector<JointPose> out(5);
  CHECK_FALSE(forward_kinematics(clip, 2, out));
  CHECK(out.empty());
  CHECK_FALSE(local_rotation(clip, 2, 0).has_value());
  CHECK_FALSE(local_rotation(clip, 0, 3).has_value());
  clip.values.resize(9);  // one row only, for two frames
  CHECK(forward_kinematics(clip, 0, out));
  CHECK_FALSE(forward_kinematics(clip, 1, out));
  Clip forward = tonus::test::synthetic_clip(1, 25);
  forward.joints[1].parent = 2;
  CHECK_FALSE(forward_kinematics(forward, 0, out));
  CHECK(forward_kinematics(Clip{}, 0).empty());
}

TEST_CASE("fk: a reused pose vector costs no allocation") {
  const ReadResult r = read_bvh_file(tonus::test::shared_bvh("cmu_02_walk.bvh"));
  REQUIRE(r.ok());
  std::vector<JointPose> poses;
  REQUIRE(forward_kinematics(r.clip, 0, poses));
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  tonus::test::start_counting_allocations();
  bool all = true;
  for (std::size_t f = 0; f < r.clip.frame_count; ++f) all = forward_kinematics(r.clip, f, poses) && all;
  const long allocations = tonus::test::stop_counting_allocations();
  CHECK(all);
  CHECK(allocations == 0);
}
