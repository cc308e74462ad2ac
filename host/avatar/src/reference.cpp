// The rest reference and the checks and differences of reference poses.
#include "tonus/host/avatar/reference.hpp"

#include <cmath>
#include <cstddef>

#include "reference_ops.hpp"

namespace tonus::avatar {

using std::size_t;

ReferencePose rest_reference(const sim::Model& model) {
  ReferencePose r;
  r.qpos = model.qpos0;
  r.has_velocity = true;
  return r;
}

namespace detail {
namespace {

sim::Quat quat_at(std::span<const double> q, size_t a) { return {q[a], q[a + 1], q[a + 2], q[a + 3]}; }

}  // namespace

bool reference_usable(const sim::Model& model, const ReferencePose& ref) {
  for (size_t k = 0; k < static_cast<size_t>(model.nq); ++k) {
    if (!std::isfinite(ref.qpos[k]) || std::abs(ref.qpos[k]) > 1e4) return false;
  }
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    const auto a = static_cast<size_t>(b.qpos_adr) + (b.joint == sim::JointType::free ? 3U : 0U);
    if (b.joint == sim::JointType::free || b.joint == sim::JointType::ball) {
      const double n = quat_at(ref.qpos, a).norm();
      if (!(n > 0.5 && n < 2.0)) return false;
    }
  }
  if (ref.has_velocity) {
    for (size_t k = 0; k < static_cast<size_t>(model.nv); ++k) {
      if (!(std::abs(ref.qvel[k]) < 1e3)) return false;  // false for NaN too
    }
  }
  return true;
}

void normalize(const sim::Model& model, ReferencePose& ref) {
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    if (b.joint != sim::JointType::free && b.joint != sim::JointType::ball) continue;
    const auto a = static_cast<size_t>(b.qpos_adr) + (b.joint == sim::JointType::free ? 3U : 0U);
    const double n = quat_at(ref.qpos, a).norm();
    for (size_t k = 0; k < 4; ++k) ref.qpos[a + k] /= n;
  }
}

StepSize step_size(const sim::Model& model, std::span<const double> q0, std::span<const double> q1) {
  StepSize s;
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    const auto a = static_cast<size_t>(b.qpos_adr);
    switch (b.joint) {
      case sim::JointType::free:
        s.root_m = (sim::Vec3(q1[a], q1[a + 1], q1[a + 2]) - sim::Vec3(q0[a], q0[a + 1], q0[a + 2])).norm();
        s.joint_rad = std::max(s.joint_rad, sim::quat_between(quat_at(q0, a + 3), quat_at(q1, a + 3)).norm());
        break;
      case sim::JointType::ball:
        s.joint_rad = std::max(s.joint_rad, sim::quat_between(quat_at(q0, a), quat_at(q1, a)).norm());
        break;
      case sim::JointType::hinge: s.joint_rad = std::max(s.joint_rad, std::abs(q1[a] - q0[a])); break;
      case sim::JointType::fixed: break;
    }
  }
  return s;
}

void difference(const sim::Model& model, std::span<const double> q0, std::span<const double> q1, double dt_s,
                std::span<double> qvel) {
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    const auto a = static_cast<size_t>(b.qpos_adr);
    const auto d = static_cast<size_t>(b.dof_adr);
    switch (b.joint) {
      case sim::JointType::free: {
        for (size_t k = 0; k < 3; ++k) qvel[d + k] = (q1[a + k] - q0[a + k]) / dt_s;
        const sim::Vec3 w = sim::quat_between(quat_at(q0, a + 3), quat_at(q1, a + 3)) / dt_s;
        for (size_t k = 0; k < 3; ++k) qvel[d + 3 + k] = w(static_cast<Eigen::Index>(k));
        break;
      }
      case sim::JointType::ball: {
        const sim::Vec3 w = sim::quat_between(quat_at(q0, a), quat_at(q1, a)) / dt_s;
        for (size_t k = 0; k < 3; ++k) qvel[d + k] = w(static_cast<Eigen::Index>(k));
        break;
      }
      case sim::JointType::hinge: qvel[d] = (q1[a] - q0[a]) / dt_s; break;
      case sim::JointType::fixed: break;
    }
  }
}

void joint_angles_between(const sim::Model& model, std::span<const double> q0, std::span<const double> q1,
                          std::span<double> out) {
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    const auto a = static_cast<size_t>(b.qpos_adr);
    double angle = 0.0;
    if (b.joint == sim::JointType::ball) angle = sim::quat_between(quat_at(q0, a), quat_at(q1, a)).norm();
    if (b.joint == sim::JointType::hinge) angle = std::abs(q1[a] - q0[a]);
    out[static_cast<size_t>(i)] = angle;
  }
}

}  // namespace detail
}  // namespace tonus::avatar
