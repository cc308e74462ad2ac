// Bad models are refused with a message naming the field; bad inputs to the
// step are replaced by safe values and counted; a broken state is refused.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "sim_fixtures.hpp"

using namespace tonus::sim;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

BodySpec good_root() {
  BodySpec b;
  b.name = "root";
  b.joint = JointType::free;
  b.mass_kg = 2.0;
  b.inertia = box_inertia(2.0, Vec3(0.1, 0.1, 0.1));
  return b;
}

BodySpec good_child(int parent) {
  BodySpec b;
  b.name = "child";
  b.parent = parent;
  b.joint = JointType::hinge;
  b.pos_in_parent = Vec3(0, 0, -0.2);
  b.mass_kg = 1.0;
  b.inertia = box_inertia(1.0, Vec3(0.05, 0.05, 0.1));
  return b;
}

// Builds root + child after `spoil` edits them; returns the error text.
std::string error_of(const std::function<void(BodySpec&, BodySpec&, ModelBuilder&)>& spoil) {
  ModelBuilder mb;
  BodySpec root = good_root(), child = good_child(0);
  spoil(root, child, mb);
  mb.add_body(root);
  mb.add_body(child);
  const BuildResult r = mb.build();
  return r ? std::string() : r.error;
}

GeomSpec geom(int body, const Shape& shape) {
  GeomSpec g;
  g.body = body;
  g.shape = shape;
  return g;
}

}  // namespace

TEST_CASE("the builder accepts a good model and refuses each bad field, naming it") {
  CHECK(error_of([](BodySpec&, BodySpec&, ModelBuilder&) {}).empty());
  const struct {
    const char* expect;
    std::function<void(BodySpec&, BodySpec&, ModelBuilder&)> spoil;
  } cases[] = {
      {"mass_kg", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.mass_kg = 0.0; }},
      {"mass_kg", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.mass_kg = -1.0; }},
      {"mass_kg", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.mass_kg = kNaN; }},
      {"inertia is not finite", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.inertia(0, 0) = kNaN; }},
      {"positive definite", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.inertia = Mat3::Zero(); }},
      {"triangle", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.inertia = Vec3(1.0, 0.1, 0.1).asDiagonal(); }},
      {"symmetric", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.inertia(0, 1) = 0.01; }},
      {"quat_in_parent", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.quat_in_parent = Quat(2, 0, 0, 0); }},
      {"quat_in_parent", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.quat_in_parent = Quat(kNaN, 0, 0, 0); }},
      {"pos_in_parent",
       [](BodySpec&, BodySpec& c, ModelBuilder&) { c.pos_in_parent.x() = std::numeric_limits<double>::infinity(); }},
      {"hinge_axis", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.hinge_axis = Vec3::Zero(); }},
      {"parent", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.parent = 1; }},
      {"parent", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.parent = -1; }},
      {"only the root", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.joint = JointType::free; }},
      {"lower_rad",
       [](BodySpec&, BodySpec& c, ModelBuilder&) {
         c.limit.enabled = true;
         c.limit.lower_rad = 1.0;
         c.limit.upper_rad = -1.0;
       }},
      {"swing_max_rad",
       [](BodySpec&, BodySpec& c, ModelBuilder&) {
         c.joint = JointType::ball;
         c.limit.enabled = true;
         c.limit.swing_max_rad = 4.0;
       }},
      {"drive.kp", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.drive.kp = -1.0; }},
      {"drive.kd", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.drive.kd = kNaN; }},
      {"torque_limit", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.drive.torque_limit_nm = -5.0; }},
      {"armature", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.armature = -0.1; }},
      {"name is used twice", [](BodySpec& r, BodySpec& c, ModelBuilder&) { c.name = r.name; }},
      {"name is empty", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.name.clear(); }},
      {"longer", [](BodySpec&, BodySpec& c, ModelBuilder&) { c.name = std::string(40, 'x'); }},
      {"timestep_s", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.timestep(0.0); }},
      {"timestep_s", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.timestep(kNaN); }},
      {"gravity", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.gravity(Vec3(0, 0, kNaN)); }},
      {"ground: normal",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) {
         Ground g;
         g.normal = Vec3::Zero();
         mb.ground(g);
       }},
      {"restitution",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) {
         Ground g;
         g.material.restitution = 1.5;
         mb.ground(g);
       }},
      {"iterations",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) {
         SolverOptions s;
         s.iterations = 0;
         mb.solver(s);
       }},
      {"rk4", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.integrator(Integrator::rk4); }},
      {"geom 0: body index", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.add_geom(geom(5, Shape::sphere(0.1))); }},
      {"geom 0: shape sizes",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.add_geom(geom(1, Shape::capsule(0.0, 0.1))); }},
      {"geom 0: shape sizes",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.add_geom(geom(1, Shape::box(Vec3(0.1, kNaN, 0.1)))); }},
      {"planes belong", [](BodySpec&, BodySpec&, ModelBuilder& mb) { mb.add_geom(geom(1, Shape::plane())); }},
      {"local.rot",
       [](BodySpec&, BodySpec&, ModelBuilder& mb) {
         GeomSpec g = geom(1, Shape::sphere(0.1));
         g.local.rot = 2.0 * Mat3::Identity();
         mb.add_geom(g);
       }},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.spoil);
    INFO("expected an error mentioning '" << c.expect << "', got '" << e << "'");
    CHECK(e.find(c.expect) != std::string::npos);
  }
}

TEST_CASE("the builder refuses models over capacity") {
  ModelBuilder mb;
  mb.add_body(good_root());
  for (std::size_t i = 1; i <= kMaxBodies; ++i) {
    BodySpec c = good_child(static_cast<int>(i) - 1);
    c.name = std::to_string(i);  // (not "b" + ...: a GCC 12 -Wrestrict false positive at -O3)
    mb.add_body(c);
  }
  const BuildResult r = mb.build();
  CHECK_FALSE(r);
  CHECK(r.error.find("kMaxBodies") != std::string::npos);

  ModelBuilder dofs;
  dofs.add_body(good_root());
  for (std::size_t i = 1; i < kMaxBodies; ++i) {  // ball joints: 6 + 31 * 3 dofs > kMaxDofs
    BodySpec c = good_child(0);
    c.name = std::to_string(i);  // (not "b" + ...: a GCC 12 -Wrestrict false positive at -O3)
    c.joint = JointType::ball;
    dofs.add_body(c);
  }
  const BuildResult r2 = dofs.build();
  CHECK_FALSE(r2);
  CHECK(r2.error.find("kMaxDofs") != std::string::npos);
}

TEST_CASE("the humanoid builder refuses absurd bodies") {
  HumanoidSpec s;
  s.height_m = -1.0;
  CHECK(build_humanoid(s).error.find("height_m") != std::string::npos);
  s = HumanoidSpec{};
  s.mass_kg = kNaN;
  CHECK(build_humanoid(s).error.find("mass_kg") != std::string::npos);
  s = HumanoidSpec{};
  auto bones = default_skeleton(1.7);
  bones[index(Bone::LeftLowerArm)] = Vec3(kNaN, 0, 0);
  s.bone_offsets = bones;
  CHECK(build_humanoid(s).error.find("LeftLowerArm") != std::string::npos);
  bones = default_skeleton(1.7);
  bones[index(Bone::RightFoot)] = Vec3::Zero();
  s.bone_offsets = bones;
  CHECK(build_humanoid(s).error.find("RightFoot") != std::string::npos);
  s = HumanoidSpec{};
  s.drive_frequency_hz = 0.0;
  CHECK(build_humanoid(s).error.find("drive_frequency_hz") != std::string::npos);
}

TEST_CASE("non-finite or absurd step inputs are replaced by safe values, counted, and nothing turns NaN") {
  const auto model = test::humanoid(Features{});
  const std::size_t elbow = index(Bone::LeftLowerArm), shoulder = index(Bone::LeftUpperArm);
  const struct {
    const char* what;
    std::function<void(const Model&, StepInputs&)> spoil;
  } cases[] = {
      {"NaN hinge target",
       [&](const Model& m, StepInputs& in) {
         in.target_qpos[static_cast<std::size_t>(m.bodies[elbow].qpos_adr)] = kNaN;
       }},
      {"NaN ball target",
       [&](const Model& m, StepInputs& in) {
         in.target_qpos[static_cast<std::size_t>(m.bodies[shoulder].qpos_adr) + 1] = kNaN;
       }},
      {"zero ball target",
       [&](const Model& m, StepInputs& in) {
         for (std::size_t k = 0; k < 4; ++k)
           in.target_qpos[static_cast<std::size_t>(m.bodies[shoulder].qpos_adr) + k] = 0.0;
       }},
      {"NaN kp",
       [&](const Model& m, StepInputs& in) { in.kp[static_cast<std::size_t>(m.bodies[elbow].dof_adr)] = kNaN; }},
      {"negative kd",
       [&](const Model& m, StepInputs& in) { in.kd[static_cast<std::size_t>(m.bodies[elbow].dof_adr)] = -3.0; }},
      {"infinite torque limit",
       [&](const Model&, StepInputs& in) { in.torque_limit_nm[elbow] = std::numeric_limits<double>::infinity(); }},
      {"NaN feedforward",
       [&](const Model& m, StepInputs& in) { in.tau_ff[static_cast<std::size_t>(m.bodies[elbow].dof_adr)] = kNaN; }},
      {"absurd feedforward",
       [&](const Model& m, StepInputs& in) { in.tau_ff[static_cast<std::size_t>(m.bodies[elbow].dof_adr)] = 1e30; }},
      {"NaN target velocity",
       [&](const Model& m, StepInputs& in) {
         in.target_qvel[static_cast<std::size_t>(m.bodies[elbow].dof_adr)] = kNaN;
       }},
      {"NaN servo gain",
       [&](const Model&, StepInputs& in) {
         in.root_servo.enabled = true;
         in.root_servo.kp_lin = kNaN;
       }},
      {"NaN root reference (servo)",
       [&](const Model&, StepInputs& in) {
         in.root_servo = {true, 1e4, 1e3, 1e4, 1e3};
         in.root_pos.x() = kNaN;
       }},
  };
  for (const auto& c : cases) {
    INFO(c.what);
    auto data = make_data(*model);
    StepInputs in = make_inputs(*model);
    c.spoil(*model, in);
    for (int s = 0; s < 200; ++s) CHECK(step(*model, *data, in) != StepStatus::diverged);
    for (int k = 0; k < model->nq; ++k) CHECK(std::isfinite(data->qpos[static_cast<std::size_t>(k)]));
    for (int k = 0; k < model->nv; ++k) {
      CHECK(std::isfinite(data->qvel[static_cast<std::size_t>(k)]));
      CHECK(std::isfinite(data->tau_pd[static_cast<std::size_t>(k)]));
    }
    CHECK(data->root_servo_force.allFinite());
  }
  // Counted where a value was replaced.
  auto data = make_data(*model);
  StepInputs in = make_inputs(*model);
  in.kp[static_cast<std::size_t>(model->bodies[elbow].dof_adr)] = kNaN;
  CHECK(step(*model, *data, in) == StepStatus::sanitized);
  CHECK(data->diag.bad_inputs == 1);

  // A kinematic root with a broken reference holds still instead.
  auto kin = make_data(*model);
  set_root_mode(*kin, RootMode::kinematic);
  in = make_inputs(*model);
  in.root_lin_vel.y() = kNaN;
  CHECK(step(*model, *kin, in) == StepStatus::sanitized);
  CHECK(kin->qvel[1] == 0.0);
}

TEST_CASE("an unnormalised target quaternion is normalised, not rejected") {
  const auto model =
      test::humanoid(Features{.gravity = false, .contacts = false, .limits = false, .self_collision = false});
  auto data = make_data(*model);
  set_root_mode(*data, RootMode::fixed);
  StepInputs in = make_inputs(*model);
  const auto a = static_cast<std::size_t>(model->bodies[index(Bone::LeftUpperArm)].qpos_adr);
  const Quat target = quat_exp(Vec3(0.0, 0.0, 0.4));
  in.target_qpos[a] = 1.7 * target.w();
  in.target_qpos[a + 1] = 1.7 * target.x();
  in.target_qpos[a + 2] = 1.7 * target.y();
  in.target_qpos[a + 3] = 1.7 * target.z();
  for (int s = 0; s < 3000; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
  const Quat q(data->qpos[a], data->qpos[a + 1], data->qpos[a + 2], data->qpos[a + 3]);
  CHECK(q.angularDistance(target) < 1e-3);
}

TEST_CASE("a state broken by the caller is refused, reported, and a reset recovers") {
  const auto model = test::humanoid(Features{});
  auto data = make_data(*model);
  data->qvel[10] = kNaN;
  const StepInputs in = make_inputs(*model);
  CHECK(step(*model, *data, in) == StepStatus::diverged);
  CHECK(data->diag.divergences == 1);
  reset_data(*model, *data);
  CHECK(step(*model, *data, in) == StepStatus::ok);
}
