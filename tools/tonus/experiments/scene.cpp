// Shared pieces of the experiments.
#include "scene.hpp"

#include <cmath>

#include "tonus/sim/step.hpp"

namespace tonus::experiments {

using sim::Bone;

std::unique_ptr<sim::Model> humanoid_model(std::string& error) {
  sim::BuildResult r = sim::build_humanoid(sim::HumanoidSpec{});
  if (!r) {
    error = r.error;
    return nullptr;
  }
  return std::move(r.model);
}

Pose::Pose(const sim::Model& m) : m_(&m), ref_(avatar::rest_reference(m)) {}

Pose& Pose::ball(Bone b, const sim::Quat& q) {
  const auto a = static_cast<std::size_t>(m_->bodies[sim::index(b)].qpos_adr);
  ref_.qpos[a] = q.w();
  ref_.qpos[a + 1] = q.x();
  ref_.qpos[a + 2] = q.y();
  ref_.qpos[a + 3] = q.z();
  return *this;
}

Pose& Pose::hinge(Bone b, double angle_rad) {
  ref_.qpos[static_cast<std::size_t>(m_->bodies[sim::index(b)].qpos_adr)] = angle_rad;
  return *this;
}

avatar::ReferencePose forearm_forward_pose(const sim::Model& m) {
  // The right arm hangs 1 rad below the T-pose (a turn about +X); the elbow
  // flexes 90 degrees about its axis, so the forearm points forward (+X); the
  // elbow axis, the hand's broad-face normal at rest, is then tilted by 1 rad,
  // which the wrist's twist (about the bone, rest -Y) undoes: the hand lies level.
  constexpr double kLowered = 1.0;
  return Pose(m)
      .ball(Bone::RightUpperArm, sim::Quat(Eigen::AngleAxisd(kLowered, sim::Vec3::UnitX())))
      .hinge(Bone::RightLowerArm, M_PI / 2.0)
      .ball(Bone::RightHand, sim::Quat(Eigen::AngleAxisd(kLowered, sim::Vec3::UnitY())))
      .ball(Bone::LeftUpperArm, sim::Quat(Eigen::AngleAxisd(-1.3, sim::Vec3::UnitX())))
      .reference();
}

avatar::ReferencePose arms_down_pose(const sim::Model& m) {
  return Pose(m)
      .ball(Bone::RightUpperArm, sim::Quat(Eigen::AngleAxisd(1.3, sim::Vec3::UnitX())))
      .ball(Bone::LeftUpperArm, sim::Quat(Eigen::AngleAxisd(-1.3, sim::Vec3::UnitX())))
      .reference();
}

Kinematics::Kinematics(const sim::Model& m) : m_(&m), d_(sim::make_data(m)) {}

const sim::Data& Kinematics::at(const std::array<double, sim::kMaxQpos>& qpos) {
  d_->qpos = qpos;
  d_->qvel.fill(0.0);
  sim::forward_kinematics(*m_, *d_);
  return *d_;
}

sim::Vec3 shape_centre(const sim::Model& m, const sim::Data& d, Bone b) {
  const int g = m.first_geom(static_cast<int>(sim::index(b)));
  return g >= 0 ? d.xgeom[static_cast<std::size_t>(g)].pos : d.xbody[sim::index(b)].pos;
}

}  // namespace tonus::experiments
