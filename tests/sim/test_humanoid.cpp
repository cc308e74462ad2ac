// The humanoid builder: HumanBodyBones names and tree, de Leva masses, centres
// of mass and inertias, a skeleton that stands on the ground, symmetric sides.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "sim_fixtures.hpp"

using namespace tonus::sim;

namespace {

double de_leva_total(Sex sex) { return total_mass_fraction(sex); }

}  // namespace

TEST_CASE("humanoid: 21 bodies named and linked as HumanBodyBones, 54 dofs") {
  const BuildResult r = build_humanoid(HumanoidSpec{});
  REQUIRE_MESSAGE(r, r.error);
  const Model& m = *r.model;
  REQUIRE(m.nbody == static_cast<int>(kBoneCount));
  for (std::size_t i = 0; i < kBoneCount; ++i) {
    CHECK(m.bodies[i].name_view() == kBones[i].name);
    CHECK(m.bodies[i].parent == (kBones[i].parent ? static_cast<int>(index(*kBones[i].parent)) : -1));
  }
  CHECK(m.bodies[0].joint == JointType::free);
  for (const Bone b : {Bone::LeftLowerArm, Bone::RightLowerArm, Bone::LeftLowerLeg, Bone::RightLowerLeg, Bone::LeftToes,
                       Bone::RightToes}) {
    CHECK(m.bodies[index(b)].joint == JointType::hinge);
  }
  CHECK(m.nv == 6 + 14 * 3 + 6);
  CHECK(m.ngeom == static_cast<int>(kBoneCount));
}

TEST_CASE("humanoid: masses, centres of mass and inertias follow de Leva (1996)") {
  for (const Sex sex : {Sex::male, Sex::female}) {
    HumanoidSpec spec;
    spec.sex = sex;
    spec.mass_kg = 72.0;
    const BuildResult r = build_humanoid(spec);
    REQUIRE(r);
    const Model& m = *r.model;
    CHECK(m.total_mass_kg() == doctest::Approx(72.0).epsilon(1e-12));
    const double scale = 72.0 / de_leva_total(sex);
    const SegmentParams thigh = de_leva(Segment::thigh, sex);
    const Body& upper_leg = m.bodies[index(Bone::LeftUpperLeg)];
    CHECK(upper_leg.mass_kg == doctest::Approx(thigh.mass_fraction * scale).epsilon(1e-12));
    const double thigh_len = m.bodies[index(Bone::LeftLowerLeg)].pos_in_parent.norm();
    CHECK(upper_leg.com.norm() == doctest::Approx(thigh.com_fraction * thigh_len).epsilon(1e-12));
    // The longitudinal principal moment: m (r_long L)^2, about the bone (z here).
    const double i_long = upper_leg.mass_kg * std::pow(thigh.rg_longitudinal * thigh_len, 2);
    CHECK(upper_leg.inertia(2, 2) == doctest::Approx(i_long).epsilon(1e-9));
    const SegmentParams forearm = de_leva(Segment::forearm, sex);
    const Body& lower_arm = m.bodies[index(Bone::RightLowerArm)];
    CHECK(lower_arm.mass_kg == doctest::Approx(forearm.mass_fraction * scale).epsilon(1e-12));
    // The forearm lies along -y in the T-pose: its longitudinal moment is about y.
    const double arm_len = m.bodies[index(Bone::RightHand)].pos_in_parent.norm();
    CHECK(lower_arm.inertia(1, 1) ==
          doctest::Approx(lower_arm.mass_kg * std::pow(forearm.rg_longitudinal * arm_len, 2)).epsilon(1e-9));
    // The head and neck together weigh de Leva's head segment.
    const double head_neck = m.bodies[index(Bone::Head)].mass_kg + m.bodies[index(Bone::Neck)].mass_kg;
    CHECK(head_neck == doctest::Approx(de_leva(Segment::head, sex).mass_fraction * scale).epsilon(1e-12));
    // Every inertia is physical (the builder would refuse it otherwise) and every body has a shape.
    for (int i = 0; i < m.nbody; ++i) {
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(m.bodies[static_cast<std::size_t>(i)].inertia);
      CHECK(eig.eigenvalues().minCoeff() > 0.0);
    }
  }
}

TEST_CASE("humanoid: the default skeleton stands on z = 0, is about as tall as asked, and is left-right symmetric") {
  HumanoidSpec spec;
  spec.height_m = 1.80;
  const BuildResult r = build_humanoid(spec);
  REQUIRE(r);
  const Model& m = *r.model;
  auto d = make_data(m);
  double lowest = 1e9, highest = -1e9;
  for (int g = 0; g < m.ngeom; ++g) {
    const Geom& geom = m.geoms[static_cast<std::size_t>(g)];
    const Pose& x = d->xgeom[static_cast<std::size_t>(g)];
    double bottom = x.pos.z(), top = x.pos.z();
    if (geom.shape.type == ShapeType::box) {
      const double extent = (x.rot.cwiseAbs() * geom.shape.half_extents_m).z();
      bottom -= extent;
      top += extent;
    } else {
      const double extent = geom.shape.radius_m + geom.shape.half_length_m * std::abs(x.rot(2, 2));
      bottom -= extent;
      top += extent;
    }
    lowest = std::min(lowest, bottom);
    highest = std::max(highest, top);
  }
  CHECK(lowest == doctest::Approx(0.0).scale(1.0).epsilon(1e-3));
  CHECK(highest == doctest::Approx(1.80).epsilon(0.05));
  for (std::size_t i = 0; i < kBoneCount; ++i) {
    const Bone b = kBones[i].bone;
    const Body& left = m.bodies[i];
    const Body& right = m.bodies[index(mirror(b))];
    CHECK(left.mass_kg == right.mass_kg);
    CHECK(left.pos_in_parent.y() == doctest::Approx(-right.pos_in_parent.y()));
    CHECK(left.drive.kp == doctest::Approx(right.drive.kp));
  }
}

TEST_CASE("humanoid: limits on every joint, gains and torque limits positive, scaled with body mass") {
  HumanoidSpec light, heavy;
  light.mass_kg = 50.0;
  heavy.mass_kg = 100.0;
  const BuildResult a = build_humanoid(light), b = build_humanoid(heavy);
  REQUIRE(a);
  REQUIRE(b);
  for (std::size_t i = 1; i < kBoneCount; ++i) {
    const Body& x = a.model->bodies[i];
    CHECK(x.limit.enabled);
    CHECK(x.drive.kp > 0.0);
    CHECK(x.drive.kd > 0.0);
    CHECK(x.drive.torque_limit_nm > 0.0);
    CHECK(b.model->bodies[i].drive.torque_limit_nm == doctest::Approx(2.0 * x.drive.torque_limit_nm));
    CHECK(b.model->bodies[i].drive.kp == doctest::Approx(2.0 * x.drive.kp));  // inertia scales with mass
  }
}

TEST_CASE("humanoid: a custom skeleton sets the bone lengths, the masses stay de Leva's") {
  HumanoidSpec spec;
  auto bones = default_skeleton(1.70);
  for (Vec3& v : bones) v *= 1.1;  // a taller skeleton than the stated height: the offsets win
  spec.bone_offsets = bones;
  const BuildResult r = build_humanoid(spec);
  REQUIRE(r);
  const BuildResult base = build_humanoid(HumanoidSpec{});
  for (std::size_t i = 1; i < kBoneCount; ++i) {
    CHECK(r.model->bodies[i].pos_in_parent.isApprox(1.1 * base.model->bodies[i].pos_in_parent));
    CHECK(r.model->bodies[i].mass_kg == doctest::Approx(base.model->bodies[i].mass_kg));
  }
}
