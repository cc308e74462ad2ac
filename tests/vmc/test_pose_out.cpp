// pose_from_qpos: known values by hand, then the whole chain against sim's
// own forward kinematics (the Unity bones composed root to leaves must land
// where the humanoid's bodies are, converted), and bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/host/vmc/unity_frame.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/step.hpp"
#include "vmc_fixtures.hpp"

using namespace tonus;
using sim::Bone;
using sim::Quat;
using sim::Vec3;

namespace {

std::vector<double> rest_qpos() {
  const sim::Model& m = vmc::test::humanoid();
  return {m.qpos0.begin(), m.qpos0.begin() + m.nq};
}

double angle_between(const Quat& a, const Quat& b) { return a.angularDistance(b); }

}  // namespace

TEST_CASE("vmc pose out: the rest pose and hand-computed values") {
  const sim::Model& m = vmc::test::humanoid();
  std::vector<double> q = rest_qpos();
  q[0] = 0.0;
  q[1] = 0.0;
  q[2] = 0.95;
  vmc::VmcPose pose;
  REQUIRE(vmc::pose_from_qpos(m, q, pose));
  // Root at the origin, no rotation; the Hips carry the body: (0, 0, 0.95) -> Unity (0, 0.95, 0).
  CHECK(pose.root.pos_m.norm() == 0.0);
  CHECK(pose.root.rot.isApprox(Quat::Identity()));
  CHECK((pose.bone[0].pos_m - Vec3(0, 0.95, 0)).norm() < 1e-15);
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    CAPTURE(sim::kBones[i].name);
    CHECK(angle_between(pose.bone[i].rot, Quat::Identity()) < 1e-12);  // a T-pose rest: identity everywhere
    if (i > 0) CHECK((pose.bone[i].pos_m - vmc::to_unity(m.bodies[i].pos_in_parent)).norm() < 1e-15);
  }
  // Sides: the avatar's left is Unity -x, its right +x; the legs hang down (-y).
  CHECK(pose.bone[sim::index(Bone::LeftUpperArm)].pos_m.x() < 0.0);
  CHECK(pose.bone[sim::index(Bone::RightUpperArm)].pos_m.x() > 0.0);
  CHECK(pose.bone[sim::index(Bone::LeftUpperLeg)].pos_m.x() < 0.0);
  CHECK(pose.bone[sim::index(Bone::LeftLowerLeg)].pos_m.y() < 0.0);
  CHECK(pose.bone[sim::index(Bone::Spine)].pos_m.y() > 0.0);

  // The left upper arm raised 90 degrees about the internal +X (forward):
  // Unity (x, y, z, w) = (0, 0, -0.70711, 0.70711) (test_unity_frame.cpp derives it).
  const sim::Body& arm = m.bodies[sim::index(Bone::LeftUpperArm)];
  REQUIRE(arm.joint == sim::JointType::ball);
  const double h = std::sqrt(0.5);
  const auto a = static_cast<std::size_t>(arm.qpos_adr);
  q[a] = h;
  q[a + 1] = h;
  q[a + 2] = 0.0;
  q[a + 3] = 0.0;
  // The root turned 90 degrees left about up: Unity -90 degrees about +y.
  q[3] = h;
  q[4] = 0.0;
  q[5] = 0.0;
  q[6] = h;
  REQUIRE(vmc::pose_from_qpos(m, q, pose));
  const Quat& ua = pose.bone[sim::index(Bone::LeftUpperArm)].rot;
  CHECK(ua.x() == doctest::Approx(0.0));
  CHECK(ua.y() == doctest::Approx(0.0));
  CHECK(ua.z() == doctest::Approx(-h));
  CHECK(ua.w() == doctest::Approx(h));
  const Quat& uh = pose.bone[0].rot;
  CHECK(uh.w() == doctest::Approx(h));
  CHECK(uh.y() == doctest::Approx(-h));

  // A hinge (the left elbow): its angle about its own axis, converted.
  const sim::Body& elbow = m.bodies[sim::index(Bone::LeftLowerArm)];
  REQUIRE(elbow.joint == sim::JointType::hinge);
  const double bend = 0.5 * (elbow.limit.lower_rad + elbow.limit.upper_rad);
  q[static_cast<std::size_t>(elbow.qpos_adr)] = bend;
  REQUIRE(vmc::pose_from_qpos(m, q, pose));
  CHECK(angle_between(pose.bone[sim::index(Bone::LeftLowerArm)].rot,
                      vmc::to_unity(Quat(Eigen::AngleAxisd(bend, elbow.hinge_axis)))) < 1e-12);
}

TEST_CASE("vmc pose out: the Unity chain lands on sim's forward kinematics") {
  const sim::Model& m = vmc::test::humanoid();
  const std::vector<double> q =
      vmc::test::lively_qpos(Vec3(0.3, -0.2, 0.9), Quat(Eigen::AngleAxisd(2.0, Vec3(0.1, 0.2, 1.0).normalized())));
  vmc::VmcPose pose;
  REQUIRE(vmc::pose_from_qpos(m, q, pose));

  const std::unique_ptr<sim::Data> d = sim::make_data(m);
  std::copy(q.begin(), q.end(), d->qpos.begin());
  sim::forward_kinematics(m, *d);

  // Compose as a Unity receiver does: world = parent world * local; the root first.
  std::array<vmc::UnityTransform, sim::kBoneCount> world{};
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    const vmc::UnityTransform& parent = i == 0 ? pose.root : world[sim::index(*sim::kBones[i].parent)];
    world[i].pos_m = parent.pos_m + parent.rot * pose.bone[i].pos_m;
    world[i].rot = parent.rot * pose.bone[i].rot;
  }
  double pos_err = 0.0;
  double rot_err = 0.0;
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    pos_err = std::max(pos_err, (world[i].pos_m - vmc::to_unity(d->xbody[i].pos)).norm());
    rot_err = std::max(rot_err, angle_between(world[i].rot, vmc::to_unity(d->xquat[i])));
  }
  MESSAGE("Unity chain vs sim FK: position " << pos_err << " m, rotation " << rot_err << " rad");
  CHECK(pos_err < 1e-12);
  CHECK(rot_err < 1e-12);
  // The lively pose is lively: the left hand well above the shoulder line.
  CHECK(world[sim::index(Bone::LeftHand)].pos_m.y() > world[sim::index(Bone::LeftUpperArm)].pos_m.y() + 0.1);
}

TEST_CASE("vmc pose out: bad input leaves the pose untouched") {
  const sim::Model& m = vmc::test::humanoid();
  std::vector<double> q = rest_qpos();
  vmc::VmcPose pose;
  pose.bone[3].pos_m = Vec3(7, 7, 7);
  const vmc::VmcPose before = pose;
  const auto same = [&] { return (pose.bone[3].pos_m - before.bone[3].pos_m).norm() == 0.0; };

  CHECK_FALSE(vmc::pose_from_qpos(m, std::span<const double>(q).first(q.size() - 1), pose));
  CHECK(same());
  std::vector<double> nan = q;
  nan[10] = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(vmc::pose_from_qpos(m, nan, pose));
  CHECK(same());
  std::vector<double> zero = q;
  const auto a = static_cast<std::size_t>(m.bodies[sim::index(Bone::Head)].qpos_adr);
  for (std::size_t k = 0; k < 4; ++k) zero[a + k] = 0.0;
  CHECK_FALSE(vmc::pose_from_qpos(m, zero, pose));
  CHECK(same());
  std::vector<double> inf_root = q;
  inf_root[1] = std::numeric_limits<double>::infinity();
  CHECK_FALSE(vmc::pose_from_qpos(m, inf_root, pose));
  CHECK(same());
  sim::Model other = m;
  other.bodies[5].name[0] = 'X';  // not the humanoid's naming
  CHECK_FALSE(vmc::pose_from_qpos(other, q, pose));
  CHECK(same());
  // Unnormalised quaternions are normalised.
  std::vector<double> big = q;
  for (std::size_t k = 0; k < 4; ++k) big[a + k] *= 3.0;
  REQUIRE(vmc::pose_from_qpos(m, big, pose));
  CHECK(pose.bone[sim::index(Bone::Head)].rot.norm() == doctest::Approx(1.0));
}

TEST_CASE("vmc pose out: objects convert to Unity") {
  const vmc::VmcObject o = vmc::object_to_vmc(4, vmc::ObjectKind::cube, 0.08, Vec3(0.5, 0.1, 1.2),
                                              Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())));
  CHECK(o.id == 4);
  CHECK(std::string(vmc::to_string(o.kind)) == "cube");
  CHECK((o.pose.pos_m - Vec3(-0.1, 1.2, 0.5)).norm() < 1e-15);
  CHECK(angle_between(o.pose.rot, Quat(Eigen::AngleAxisd(-0.3, Vec3::UnitY()))) < 1e-12);
  CHECK(std::string(vmc::to_string(vmc::ObjectKind::ball)) == "ball");
}
