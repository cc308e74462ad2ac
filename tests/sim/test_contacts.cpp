// Contacts against closed forms: a resting cube carries its weight, a ball
// rebounds to e^2 h, a box sticks or slides on a slope as Coulomb says, and a
// fast ball never tunnels.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "sim_fixtures.hpp"
#include "tonus/sim/objects.hpp"

using namespace tonus::sim;

namespace {

constexpr double kG = 9.81;

// A world with only the ground: one fixed body far below, without shapes.
std::unique_ptr<Model> ground_world(const Ground& ground) {
  ModelBuilder mb;
  BodySpec anchor;
  anchor.name = "anchor";
  anchor.pos_in_parent = Vec3(0, 0, -100);
  anchor.mass_kg = 1.0;
  anchor.inertia = sphere_inertia(1.0, 0.1);
  mb.add_body(anchor);
  mb.ground(ground);
  BuildResult r = mb.build();
  REQUIRE_MESSAGE(r, r.error);
  return std::move(r.model);
}

double deepest_penetration(const Data& d, int object) {
  double worst = 0.0;
  for (int i = 0; i < d.ncon; ++i) {
    const Contact& c = d.contacts[static_cast<std::size_t>(i)];
    const bool mine = (c.a.kind == ContactSide::Kind::object && c.a.index == object) ||
                      (c.b.kind == ContactSide::Kind::object && c.b.index == object);
    if (mine) worst = std::max(worst, -c.dist_m);
  }
  return worst;
}

}  // namespace

TEST_CASE("a ball dropped on the ground rebounds to restitution^2 * h") {
  for (const double e : {0.5, 0.8, 0.95}) {
    const auto model = ground_world(Ground{});
    auto data = make_data(*model);
    const StepInputs in = make_inputs(*model);
    ObjectSpec ball;
    ball.shape = Shape::sphere(0.05);
    ball.mass_kg = 0.2;
    ball.material.restitution = e;
    const double h = 1.0;
    ball.pos = Vec3(0, 0, 0.05 + h);
    const ObjectHandle hb = add_object(*data, ball).handle;
    bool bounced = false;
    double apex = 0.0;
    for (int s = 0; s < 3000; ++s) {
      REQUIRE(step(*model, *data, in) == StepStatus::ok);
      const Object& o = *find_object(*data, hb);
      if (o.lin_vel.z() > 0.0) bounced = true;
      if (bounced) apex = std::max(apex, o.pos.z() - 0.05);
      if (bounced && o.lin_vel.z() < 0.0) break;
    }
    MESSAGE("e = " << e << ": rebound " << apex << " m, expected " << e * e * h << " m");
    CHECK(bounced);
    CHECK(apex == doctest::Approx(e * e * h).epsilon(0.05));
  }
}

TEST_CASE("a box on a 30 degree slope sticks with mu = 0.7 and slides with the analytic acceleration with mu = 0.3") {
  const double slope = M_PI / 6.0;
  const Vec3 normal(-std::sin(slope), 0.0, std::cos(slope));       // the ground rises towards +x
  const Vec3 down_slope(-std::cos(slope), 0.0, -std::sin(slope));  // along the surface, downhill
  for (const double mu : {0.7, 0.3}) {
    Ground g;
    g.normal = normal;
    g.material.friction = mu;
    const auto model = ground_world(g);
    auto data = make_data(*model);
    const StepInputs in = make_inputs(*model);
    ObjectSpec box;
    box.shape = Shape::box(Vec3::Constant(0.05));
    box.mass_kg = 1.0;
    box.material.friction = mu;
    box.quat = quat_from_two_vectors(Vec3::UnitZ(), normal);
    box.pos = 0.05 * normal;
    const ObjectHandle hb = add_object(*data, box).handle;
    for (int s = 0; s < 200; ++s) step(*model, *data, in);  // settle
    const Object& o = *find_object(*data, hb);
    const Vec3 p0 = o.pos;
    const double v0 = o.lin_vel.dot(down_slope);
    for (int s = 0; s < 1000; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
    const double v1 = o.lin_vel.dot(down_slope);
    const double moved = (o.pos - p0).dot(down_slope);
    if (mu > std::tan(slope)) {
      MESSAGE("mu = " << mu << ": moved " << moved << " m in 1 s (sticks)");
      CHECK(std::abs(moved) < 1e-3);
    } else {
      const double expected = kG * (std::sin(slope) - mu * std::cos(slope));
      const double accel = v1 - v0;  // over 1 s
      MESSAGE("mu = " << mu << ": acceleration " << accel << " m/s^2, analytic " << expected);
      CHECK(accel == doctest::Approx(expected).epsilon(0.05));
    }
  }
}

TEST_CASE("a 0.1 m ball at 10 m/s does not tunnel through the ground, a thin plate or the humanoid") {
  // A 0.1 m ball shot straight down at 10 m/s from `height`; the lowest its bottom gets.
  const auto shoot_down = [](bool with_plate, double height) {
    const auto model = ground_world(Ground{});
    auto data = make_data(*model);
    if (with_plate) {
      ObjectSpec plate;
      plate.shape = Shape::box(Vec3(0.25, 0.25, 0.005));
      plate.mass_kg = 2.0;
      plate.pos = Vec3(0, 0, 0.005);
      add_object(*data, plate);
    }
    ObjectSpec ball;
    ball.shape = Shape::sphere(0.05);
    ball.mass_kg = 0.4;
    ball.pos = Vec3(0, 0, height);
    ball.lin_vel = Vec3(0, 0, -10);
    const ObjectHandle hb = add_object(*data, ball).handle;
    double lowest = 1.0;
    for (int s = 0; s < 300; ++s) {
      step(*model, *data, make_inputs(*model));
      lowest = std::min(lowest, find_object(*data, hb)->pos.z() - 0.05);
    }
    return lowest;
  };
  SUBCASE("into the ground") { CHECK(shoot_down(false, 0.2) > -2e-3); }
  SUBCASE("into a 1 cm plate lying on the ground") {
    const double lowest = shoot_down(true, 0.3);
    MESSAGE("lowest point of the ball " << lowest << " m (plate top at 0.01 m)");
    CHECK(lowest > 0.01 - 2e-3);
  }
  SUBCASE("into the humanoid's chest, head on") {
    const auto model = test::humanoid(Features{});
    auto data = make_data(*model);
    set_root_mode(*data, RootMode::fixed);
    const Pose chest = data->xgeom[index(Bone::Chest)];
    ObjectSpec ball;
    ball.shape = Shape::sphere(0.05);
    ball.mass_kg = 0.4;
    ball.pos = chest.pos + Vec3(0.5, 0, 0);
    ball.lin_vel = Vec3(-10, 0, 0);
    const ObjectHandle hb = add_object(*data, ball).handle;
    double closest = 1.0;
    for (int s = 0; s < 200; ++s) {
      REQUIRE(step(*model, *data, make_inputs(*model)) != StepStatus::diverged);
      closest = std::min(closest, find_object(*data, hb)->pos.x() - data->xgeom[index(Bone::Chest)].pos.x());
    }
    const Object& o = *find_object(*data, hb);
    MESSAGE("ball centre came within " << closest << " m of the chest axis; it leaves at " << o.lin_vel.x() << " m/s");
    CHECK(closest > 0.05);       // never inside the chest capsule (radius ~0.09 m)
    CHECK(o.lin_vel.x() > 0.0);  // and it bounced back
  }
}

TEST_CASE("a 1 kg cube resting on an open hand held by its drives: normal force = m g within 2 %, penetration < 2 mm") {
  const auto model = test::humanoid(Features{});
  auto data = make_data(*model);
  set_root_mode(*data, RootMode::fixed);
  StepInputs in = make_inputs(*model);
  for (int i = 1; i < model->nbody; ++i) {
    scale_joint_gains(*model, in, i, 25.0, 5.0);  // a firm hold: 20 Hz instead of the default 4 Hz
    in.torque_limit_nm[static_cast<std::size_t>(i)] = 0.0;
  }
  // Gravity feedforward of the arm at rest (the dual scheme's simulation A provides it in tonus).
  std::array<double, kMaxDofs> zero{};
  inverse_dynamics(*model, *data, zero, in.tau_ff);
  const Pose hand = data->xgeom[index(Bone::LeftHand)];
  const double top = hand.pos.z() + model->geoms[index(Bone::LeftHand)].shape.half_extents_m.z();
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.04));
  cube.mass_kg = 1.0;
  cube.material.friction = 1.0;
  cube.pos = Vec3(hand.pos.x(), hand.pos.y(), top + 0.04 + 0.01);
  const AddObjectResult added = add_object(*data, cube);
  REQUIRE(added.error == ObjectError::none);
  for (int s = 0; s < 2000; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
  const int slot = added.handle.slot;
  const double weight = kG * cube.mass_kg;
  double force = 0.0;
  int points = 0;
  for (int i = 0; i < data->ncon; ++i) {
    const Contact& c = data->contacts[static_cast<std::size_t>(i)];
    if (c.a.kind == ContactSide::Kind::object && c.a.index == slot && c.b.kind == ContactSide::Kind::body) {
      force += c.force_world.z();  // vertical support, friction included
      ++points;
    }
  }
  const double pen = deepest_penetration(*data, slot);
  MESSAGE("cube on hand: " << points << " contact points, vertical force " << force << " N (m g = " << weight
                           << " N), penetration " << pen * 1e3 << " mm");
  CHECK(points >= 3);
  CHECK(force == doctest::Approx(weight).epsilon(0.02));
  CHECK(pen < 2e-3);
  CHECK(find_object(*data, added.handle)->lin_vel.norm() < 1e-3);
}

TEST_CASE("the humanoid standing on its feet: the ground carries its weight") {
  const auto model = test::humanoid(Features{});
  auto data = make_data(*model);
  StepInputs in = make_inputs(*model);
  for (int i = 1; i < model->nbody; ++i) {
    scale_joint_gains(*model, in, i, 100.0, 10.0);  // a statue: 40 Hz
    in.torque_limit_nm[static_cast<std::size_t>(i)] = 0.0;
  }
  for (int s = 0; s < 2000; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
  double force = 0.0;
  for (int i = 0; i < data->ncon; ++i) {
    const Contact& c = data->contacts[static_cast<std::size_t>(i)];
    if (c.b.kind == ContactSide::Kind::ground) force += c.force_world.z();
  }
  MESSAGE("standing: " << data->ncon << " contacts, ground force " << force << " N for a weight of "
                       << model->total_mass_kg() * kG << " N; hips at " << data->qpos[2] << " m");
  CHECK(force == doctest::Approx(model->total_mass_kg() * kG).epsilon(0.02));
  CHECK(data->qpos[2] == doctest::Approx(model->qpos0[2]).epsilon(0.02));
}

TEST_CASE("objects: add, remove, stale handles, capacity, bad specs") {
  const auto model = ground_world(Ground{});
  auto data = make_data(*model);
  ObjectSpec s;
  std::array<ObjectHandle, kMaxObjects> handles;
  for (std::size_t i = 0; i < kMaxObjects; ++i) {
    s.pos = Vec3(0.3 * static_cast<double>(i), 0, 0.05);
    const AddObjectResult r = add_object(*data, s);
    REQUIRE(r.error == ObjectError::none);
    handles[i] = r.handle;
  }
  CHECK(add_object(*data, s).error == ObjectError::full);
  CHECK(remove_object(*data, handles[3]));
  CHECK_FALSE(remove_object(*data, handles[3]));  // stale now
  const AddObjectResult again = add_object(*data, s);
  CHECK(again.handle.slot == handles[3].slot);
  CHECK(find_object(*data, handles[3]) == nullptr);  // the old handle does not reach the new occupant
  CHECK(find_object(*data, again.handle) != nullptr);
  CHECK(active_object_count(*data) == static_cast<int>(kMaxObjects));

  ObjectSpec bad = s;
  bad.shape = Shape::capsule(0.1, 0.2);
  CHECK(add_object(*data, bad).error == ObjectError::bad_shape);
  bad = s;
  bad.mass_kg = -1.0;
  CHECK(add_object(*data, bad).error == ObjectError::bad_mass);
  bad = s;
  bad.pos.x() = std::nan("");
  CHECK(add_object(*data, bad).error == ObjectError::bad_pose);
  bad = s;
  bad.quat = Quat(0, 0, 0, 0);
  CHECK(add_object(*data, bad).error == ObjectError::bad_pose);
  bad = s;
  bad.lin_vel.y() = std::numeric_limits<double>::infinity();
  CHECK(add_object(*data, bad).error == ObjectError::bad_velocity);
  bad = s;
  bad.material.restitution = 2.0;
  CHECK(add_object(*data, bad).error == ObjectError::bad_material);
  bad = s;
  bad.shape = Shape::sphere(0.0);
  CHECK(add_object(*data, bad).error == ObjectError::bad_shape);
}

TEST_CASE("more contact points than the capacity: counted, dropped, never a crash") {
  auto model = test::humanoid(Features{});
  model->solver.max_contacts = 64;
  auto data = make_data(*model);
  set_root_mode(*data, RootMode::fixed);
  ObjectSpec box;
  box.shape = Shape::box(Vec3::Constant(0.05));
  for (std::size_t i = 0; i < 24; ++i) {
    box.pos = Vec3(1.0 + 0.2 * static_cast<double>(i % 4), 0.2 * static_cast<double>(i >> 2U), 0.05);
    REQUIRE(add_object(*data, box).error == ObjectError::none);
  }
  const StepInputs in = make_inputs(*model);
  for (int s = 0; s < 100; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
  CHECK(data->ncon == 64);
  CHECK(data->diag.contact_overflow > 0);
  // One point under each box is kept before any box gets a second.
  std::array<int, kMaxObjects> points{};
  for (int c = 0; c < data->ncon; ++c) {
    const Contact& k = data->contacts[static_cast<std::size_t>(c)];
    if (k.a.kind == ContactSide::Kind::object) ++points[static_cast<std::size_t>(k.a.index)];
  }
  for (std::size_t i = 0; i < 24; ++i) CHECK(points[i] >= 1);
}
