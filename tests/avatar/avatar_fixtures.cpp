// Shared fixtures of the avatar tests.
#include "avatar_fixtures.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::avatar::test {

using std::size_t;

const sim::Model& humanoid() {
  static const sim::Model model = [] {
    const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
    REQUIRE_MESSAGE(built, built.error);
    return *built.model;
  }();
  return model;
}

AvatarController make_controller(const AvatarConfig& config) {
  AvatarController::Created made = AvatarController::create(humanoid(), config);
  REQUIRE_MESSAGE(made, made.error);
  return std::move(*made.controller);
}

void set_ball(ReferencePose& ref, sim::Bone bone, const sim::Quat& q) {
  const sim::Body& b = humanoid().bodies[sim::index(bone)];
  REQUIRE(b.joint == sim::JointType::ball);
  const auto a = static_cast<size_t>(b.qpos_adr);
  ref.qpos[a] = q.w();
  ref.qpos[a + 1] = q.x();
  ref.qpos[a + 2] = q.y();
  ref.qpos[a + 3] = q.z();
}

void set_hinge(ReferencePose& ref, sim::Bone bone, double angle_rad) {
  const sim::Body& b = humanoid().bodies[sim::index(bone)];
  REQUIRE(b.joint == sim::JointType::hinge);
  ref.qpos[static_cast<size_t>(b.qpos_adr)] = angle_rad;
}

ReferencePose arms_lowered(double lower_rad, double elbow_rad) {
  ReferencePose r = rest_reference(humanoid());
  // The right arm points along -Y: a positive turn about +X lowers it; the left's mirror.
  set_ball(r, sim::Bone::RightUpperArm, sim::Quat(Eigen::AngleAxisd(lower_rad, sim::Vec3::UnitX())));
  set_ball(r, sim::Bone::LeftUpperArm, sim::Quat(Eigen::AngleAxisd(-lower_rad, sim::Vec3::UnitX())));
  set_hinge(r, sim::Bone::RightLowerArm, elbow_rad);
  set_hinge(r, sim::Bone::LeftLowerArm, elbow_rad);
  return r;
}

sim::Vec3 com_of(std::span<const double> qpos, sim::Bone bone) {
  static std::unique_ptr<sim::Data> scratch = sim::make_data(humanoid());
  const sim::Model& m = humanoid();
  std::copy_n(qpos.begin(), m.nq, scratch->qpos.begin());
  scratch->qvel.fill(0.0);
  sim::forward_kinematics(m, *scratch);
  return scratch->xcom[sim::index(bone)];
}

sim::Vec3 com_of(const TickOutput& out, sim::Bone bone) {
  return out.bones[sim::index(bone)].apply(humanoid().bodies[sim::index(bone)].com);
}

double joint_norm(std::span<const double> tau, int body) {
  const sim::Body& b = humanoid().bodies[static_cast<size_t>(body)];
  double n2 = 0.0;
  for (int k = b.dof_adr; k < b.dof_adr + b.dof_num; ++k)
    n2 += tau[static_cast<size_t>(k)] * tau[static_cast<size_t>(k)];
  return std::sqrt(n2);
}

double worst_limit_ratio(std::span<const double> tau) {
  const sim::Model& m = humanoid();
  double worst = 0.0;
  for (int i = 1; i < m.nbody; ++i) {
    const double limit = m.bodies[static_cast<size_t>(i)].drive.torque_limit_nm;
    if (limit > 0.0) worst = std::max(worst, joint_norm(tau, i) / limit);
  }
  return worst;
}

bool all_finite(const TickOutput& out) {
  const auto finite = [](std::span<const double> v) {
    for (const double x : v) {
      if (!std::isfinite(x)) return false;
    }
    return true;
  };
  bool ok = std::isfinite(out.time_s) && finite(out.qpos) && finite(out.qvel) && finite(out.reference_qpos) &&
            finite(out.deviation_rad) && finite(out.tau_a) && finite(out.tau_b) && finite(out.tau_ff) &&
            finite(out.stiffness) && out.root_force.allFinite() && out.root_torque.allFinite();
  for (const sim::Pose& p : out.bones) ok = ok && p.pos.allFinite() && p.rot.allFinite();
  for (int e = 0; e < out.nevents; ++e) {
    const ContactEvent& c = out.events[static_cast<size_t>(e)];
    ok = ok && std::isfinite(c.impulse_ns) && c.point.allFinite() && c.normal.allFinite();
  }
  return ok;
}

}  // namespace tonus::avatar::test
