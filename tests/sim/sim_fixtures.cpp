#include "sim_fixtures.hpp"

#include <doctest/doctest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "tonus/sim/objects.hpp"

namespace tonus::sim::test {

std::unique_ptr<Model> humanoid(const Features& features, Integrator integrator, const HumanoidSpec& spec) {
  std::string error;
  ModelBuilder mb = humanoid_builder(spec, error);
  REQUIRE_MESSAGE(error.empty(), error);
  mb.features(features).integrator(integrator);
  BuildResult r = mb.build();
  REQUIRE_MESSAGE(r, r.error);
  return std::move(r.model);
}

bool add_cube_on_right_hand(const Model& model, Data& data) {
  const std::size_t hand = index(Bone::RightHand);
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.04));
  cube.mass_kg = 1.0;
  cube.pos = data.xgeom[hand].pos + Vec3(0, 0, model.geoms[hand].shape.half_extents_m.z() + 0.041);
  return add_object(data, cube).handle.valid();
}

Mujoco::Mujoco(const std::string& xml) {
  char path[] = "/tmp/tonus-mjcf-XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  if (fd < 0) {
    error_ = "cannot create a temporary file";
    return;
  }
  close(fd);
  std::ofstream(path) << xml;
  char err[1024] = {0};
  model_ = mj_loadXML(path, nullptr, err, sizeof err);
  std::remove(path);
  if (model_ == nullptr) {
    error_ = err;
    return;
  }
  data_ = mj_makeData(model_);
}

Mujoco::~Mujoco() {
  if (data_ != nullptr) mj_deleteData(data_);
  if (model_ != nullptr) mj_deleteModel(model_);
}

void random_joint_pose(const Model& model, std::span<double> qpos, unsigned seed, double spread) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, spread);
  std::uniform_real_distribution<double> inside(0.25, 0.75);
  for (int i = 1; i < model.nbody; ++i) {
    const Body& b = model.bodies[static_cast<std::size_t>(i)];
    const auto q = static_cast<std::size_t>(b.qpos_adr);
    if (b.joint == JointType::ball) {
      const Quat r = quat_exp(Vec3(n(rng), n(rng), n(rng)));
      qpos[q] = r.w();
      qpos[q + 1] = r.x();
      qpos[q + 2] = r.y();
      qpos[q + 3] = r.z();
    } else if (b.joint == JointType::hinge) {
      qpos[q] = b.limit.enabled ? b.limit.lower_rad + inside(rng) * (b.limit.upper_rad - b.limit.lower_rad) : n(rng);
    }
  }
}

StepInputs passive_inputs(const Model& model) {
  StepInputs in = make_inputs(model);
  in.kp.fill(0.0);
  in.kd.fill(0.0);
  return in;
}

double max_joint_difference(const Model& model, const double* q1, const double* q2) {
  double worst = 0.0;
  for (int i = 0; i < model.nbody; ++i) {
    const Body& b = model.bodies[static_cast<std::size_t>(i)];
    const int a = b.qpos_adr;
    const auto quat_angle = [&](int at) {
      const Quat x(q1[at], q1[at + 1], q1[at + 2], q1[at + 3]);
      const Quat y(q2[at], q2[at + 1], q2[at + 2], q2[at + 3]);
      return quat_log(x.normalized().conjugate() * y.normalized()).norm();
    };
    switch (b.joint) {
      case JointType::free:
        worst = std::max(worst, std::hypot(q1[a] - q2[a], q1[a + 1] - q2[a + 1], q1[a + 2] - q2[a + 2]));
        worst = std::max(worst, quat_angle(a + 3));
        break;
      case JointType::ball: worst = std::max(worst, quat_angle(a)); break;
      case JointType::hinge: worst = std::max(worst, std::abs(q1[a] - q2[a])); break;
      case JointType::fixed: break;
    }
  }
  return worst;
}

}  // namespace tonus::sim::test
