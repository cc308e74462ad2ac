// Joint types and limits: a welded (fixed) body moves with its parent, hinge
// ranges and ball swing cones and twist ranges hold against drives pushing
// past them, self-collision keeps limbs out of the trunk, and the step is
// deterministic to the bit.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>

#include "sim_fixtures.hpp"
#include "tonus/sim/objects.hpp"

using namespace tonus::sim;

namespace {

Features no_contacts_with_limits() {
  Features f;
  f.contacts = false;
  f.limits = true;
  return f;
}

void set_quat(StepInputs& in, const Body& b, const Quat& q) {
  const auto a = static_cast<std::size_t>(b.qpos_adr);
  in.target_qpos[a] = q.w();
  in.target_qpos[a + 1] = q.x();
  in.target_qpos[a + 2] = q.y();
  in.target_qpos[a + 3] = q.z();
}

Quat joint_quat(const Data& d, const Body& b) {
  const auto a = static_cast<std::size_t>(b.qpos_adr);
  return Quat(d.qpos[a], d.qpos[a + 1], d.qpos[a + 2], d.qpos[a + 3]).normalized();
}

}  // namespace

TEST_CASE("a body welded by a fixed joint moves as part of its parent") {
  // A pendulum rod with a welded tip mass, against one body carrying both.
  const double m1 = 1.0, m2 = 0.5, len = 0.6;
  ModelBuilder welded;
  BodySpec rod;
  rod.name = "rod";
  rod.joint = JointType::hinge;
  rod.hinge_axis = Vec3::UnitY();
  rod.mass_kg = m1;
  rod.com = Vec3(0, 0, -0.5 * len);
  rod.inertia = cylinder_inertia(m1, 0.02, 0.5 * len);
  welded.add_body(rod);
  BodySpec tip;
  tip.name = "tip";
  tip.parent = 0;
  tip.joint = JointType::fixed;
  tip.pos_in_parent = Vec3(0, 0, -len);
  tip.mass_kg = m2;
  tip.inertia = sphere_inertia(m2, 0.05);
  welded.add_body(tip);
  Features f;
  f.contacts = false;
  welded.features(f);
  const BuildResult a = welded.build();
  REQUIRE_MESSAGE(a, a.error);
  CHECK(a.model->nv == 1);

  ModelBuilder single;
  BodySpec both = rod;
  both.mass_kg = m1 + m2;
  both.com = (m1 * rod.com + m2 * Vec3(0, 0, -len)) / (m1 + m2);
  const Vec3 r1 = rod.com - both.com, r2 = Vec3(0, 0, -len) - both.com;
  const auto shift = [](double m, const Vec3& r) {
    return m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  };
  both.inertia = rod.inertia + shift(m1, r1) + tip.inertia + shift(m2, r2);
  single.add_body(both);
  single.features(f);
  const BuildResult b = single.build();
  REQUIRE(b);

  auto da = make_data(*a.model), db = make_data(*b.model);
  da->qpos[0] = db->qpos[0] = 0.7;
  const StepInputs ia = test::passive_inputs(*a.model), ib = test::passive_inputs(*b.model);
  for (int s = 0; s < 1000; ++s) {
    step(*a.model, *da, ia);
    step(*b.model, *db, ib);
  }
  CHECK(da->qpos[0] == doctest::Approx(db->qpos[0]).epsilon(1e-9));
  // The welded tip sits at the end of the rod.
  CHECK((da->xbody[1].pos - da->xbody[0].apply(Vec3(0, 0, -len))).norm() < 1e-12);
}

TEST_CASE("hinge limits hold against a drive pushing past them") {
  const auto model = test::humanoid(no_contacts_with_limits());
  auto data = make_data(*model);
  set_root_mode(*data, RootMode::fixed);
  StepInputs in = make_inputs(*model);
  const Body& elbow = model->bodies[index(Bone::LeftLowerArm)];
  const Body& knee = model->bodies[index(Bone::RightLowerLeg)];
  in.target_qpos[static_cast<std::size_t>(elbow.qpos_adr)] = 3.5;  // beyond 2.60
  in.target_qpos[static_cast<std::size_t>(knee.qpos_adr)] = -1.0;  // hyperextension beyond -0.05
  for (const std::size_t b : {index(Bone::LeftLowerArm), index(Bone::RightLowerLeg)})
    scale_joint_gains(*model, in, static_cast<int>(b), 10.0, 1.0);
  double worst_elbow = -10.0, worst_knee = 10.0;
  for (int s = 0; s < 2000; ++s) {
    REQUIRE(step(*model, *data, in) != StepStatus::diverged);
    worst_elbow = std::max(worst_elbow, data->qpos[static_cast<std::size_t>(elbow.qpos_adr)]);
    worst_knee = std::min(worst_knee, data->qpos[static_cast<std::size_t>(knee.qpos_adr)]);
  }
  MESSAGE("elbow reached " << worst_elbow << " rad (limit 2.60), knee " << worst_knee << " rad (limit -0.05)");
  CHECK(worst_elbow < elbow.limit.upper_rad + 0.01);
  CHECK(data->qpos[static_cast<std::size_t>(elbow.qpos_adr)] == doctest::Approx(elbow.limit.upper_rad).epsilon(0.005));
  CHECK(worst_knee > knee.limit.lower_rad - 0.01);
  // Without limits the same drives go past (the checks above can fail).
  const auto free_model =
      test::humanoid(Features{.gravity = true, .contacts = false, .limits = false, .self_collision = false});
  auto free = make_data(*free_model);
  set_root_mode(*free, RootMode::fixed);
  for (int s = 0; s < 2000; ++s) step(*free_model, *free, in);
  CHECK(free->qpos[static_cast<std::size_t>(elbow.qpos_adr)] > elbow.limit.upper_rad + 0.3);
}

TEST_CASE("ball joints: the swing cone and the twist range hold") {
  const auto model = test::humanoid(no_contacts_with_limits());
  const Body& hip = model->bodies[index(Bone::LeftUpperLeg)];
  const Body& neck = model->bodies[index(Bone::Neck)];
  auto data = make_data(*model);
  set_root_mode(*data, RootMode::fixed);
  StepInputs in = make_inputs(*model);
  // Swing the thigh 2.4 rad forward (cone 1.60) and twist the neck 1.6 rad (range 0.90).
  set_quat(in, hip, quat_exp(Vec3(0, -2.4, 0)));
  set_quat(in, neck, quat_exp(Vec3(0, 0, 1.6)));
  scale_joint_gains(*model, in, static_cast<int>(index(Bone::LeftUpperLeg)), 5.0, 1.0);
  scale_joint_gains(*model, in, static_cast<int>(index(Bone::Neck)), 5.0, 1.0);
  double worst_swing = 0.0, worst_twist = 0.0;
  for (int s = 0; s < 2000; ++s) {
    REQUIRE(step(*model, *data, in) != StepStatus::diverged);
    const Vec3 t = hip.limit.twist_axis;
    const Vec3 u = joint_quat(*data, hip) * t;
    worst_swing = std::max(worst_swing, std::atan2(t.cross(u).norm(), t.dot(u)));
    const Quat qn = joint_quat(*data, neck);
    worst_twist = std::max(worst_twist, std::abs(2.0 * std::atan2(qn.vec().dot(neck.limit.twist_axis), qn.w())));
  }
  MESSAGE("thigh swing reached " << worst_swing << " rad (cone 1.60), neck twist " << worst_twist << " rad (0.90)");
  CHECK(worst_swing < hip.limit.swing_max_rad + 0.02);
  CHECK(worst_swing > hip.limit.swing_max_rad - 0.05);  // it did press against the cone
  CHECK(worst_twist < neck.limit.upper_rad + 0.02);
  CHECK(worst_twist > neck.limit.upper_rad - 0.05);
}

TEST_CASE("self-collision, when enabled, keeps a hand out of the trunk") {
  // Point the right arm forward and bend the elbow: the forearm and hand sweep into the chest.
  const auto hand_in_chest = [](bool self_collision, int& body_body) {
    Features f;
    f.self_collision = self_collision;
    const auto model = test::humanoid(f);
    auto data = make_data(*model);
    set_root_mode(*data, RootMode::fixed);
    StepInputs in = make_inputs(*model);
    set_quat(in, model->bodies[index(Bone::RightUpperArm)], quat_exp(Vec3(0, 0, 1.5)));
    in.target_qpos[static_cast<std::size_t>(model->bodies[index(Bone::RightLowerArm)].qpos_adr)] = 2.4;
    body_body = 0;
    for (int s = 0; s < 2000; ++s) {
      REQUIRE(step(*model, *data, in) != StepStatus::diverged);
      for (int i = 0; i < data->ncon; ++i) {
        const Contact& c = data->contacts[static_cast<std::size_t>(i)];
        if (c.a.kind == ContactSide::Kind::body && c.b.kind == ContactSide::Kind::body) ++body_body;
      }
    }
    // How deep the hand and forearm are in the chest at the end (the narrow phase measures it).
    double deepest = 0.0;
    for (const Bone limb : {Bone::RightHand, Bone::RightLowerArm}) {
      std::array<ContactPoint, kMaxPointsPerPair> pts;
      const std::size_t n = collide(model->geoms[index(limb)].shape, data->xgeom[index(limb)],
                                    model->geoms[index(Bone::Chest)].shape, data->xgeom[index(Bone::Chest)], 0.0, pts);
      for (std::size_t k = 0; k < n; ++k) deepest = std::max(deepest, -pts[k].dist_m);
    }
    return deepest;
  };
  int with_contacts = 0, without_contacts = 0;
  const double with = hand_in_chest(true, with_contacts);
  const double without = hand_in_chest(false, without_contacts);
  MESSAGE("arm in the chest: " << with * 1e3 << " mm deep with self-collision (" << with_contacts
                               << " body-body contact points over 2 s), " << without * 1e3 << " mm without");
  CHECK(with_contacts > 0);
  CHECK(with < 5e-3);
  CHECK(without_contacts == 0);
  CHECK(without > 0.02);
}

TEST_CASE("the step is deterministic: the same inputs give the same bits") {
  const auto model = test::humanoid(Features{});
  auto run = [&] {
    auto d = make_data(*model);
    StepInputs in = make_inputs(*model);
    ObjectSpec ball;
    ball.shape = Shape::sphere(0.05);
    ball.pos = Vec3(0.6, 0.1, 1.3);
    ball.lin_vel = Vec3(-6, 0, 0);
    add_object(*d, ball);
    for (int s = 0; s < 1500; ++s) {
      in.target_qvel[10] = std::sin(0.01 * s);
      step(*model, *d, in);
    }
    return d;
  };
  const auto a = run(), b = run();
  CHECK(std::memcmp(a->qpos.data(), b->qpos.data(), sizeof(double) * static_cast<std::size_t>(model->nq)) == 0);
  CHECK(std::memcmp(a->qvel.data(), b->qvel.data(), sizeof(double) * static_cast<std::size_t>(model->nv)) == 0);
  CHECK(a->objects[0].pos == b->objects[0].pos);
}
