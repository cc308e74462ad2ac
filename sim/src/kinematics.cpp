// Forward kinematics: body and geom poses, centres of mass, the motion axis
// of every dof (and its rate) and the body velocities, all in the world frame
// with spatial vectors taken at the root (data.origin).
#include <algorithm>
#include <cstddef>

#include "spatial.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::sim {
namespace {

Quat read_quat(const std::array<double, kMaxQpos>& q, int adr) {
  const auto a = static_cast<std::size_t>(adr);
  return {q[a], q[a + 1], q[a + 2], q[a + 3]};
}

// The joint's own rotation (identity for fixed and free: a free joint's pose is read directly).
Quat joint_rotation(const Body& b, const std::array<double, kMaxQpos>& q) {
  switch (b.joint) {
    case JointType::ball: return read_quat(q, b.qpos_adr).normalized();
    case JointType::hinge: return Quat(Eigen::AngleAxisd(q[static_cast<std::size_t>(b.qpos_adr)], b.hinge_axis));
    case JointType::free:
    case JointType::fixed: break;
  }
  return Quat::Identity();
}

}  // namespace

void forward_kinematics(const Model& model, Data& data) {
  using namespace spatial;
  const auto nbody = static_cast<std::size_t>(model.nbody);
  std::copy_n(data.qpos.begin(), model.nq, data.kinematics_qpos.begin());
  std::copy_n(data.qvel.begin(), model.nv, data.kinematics_qvel.begin());
  for (std::size_t i = 0; i < nbody; ++i) {
    const Body& b = model.bodies[i];
    Quat xq;
    Vec3 xp;
    if (b.joint == JointType::free) {
      const auto a = static_cast<std::size_t>(b.qpos_adr);
      xp = Vec3(data.qpos[a], data.qpos[a + 1], data.qpos[a + 2]);
      xq = read_quat(data.qpos, b.qpos_adr + 3).normalized();
    } else if (b.parent < 0) {
      xp = b.pos_in_parent;
      xq = b.quat_in_parent * joint_rotation(b, data.qpos);
    } else {
      const auto p = static_cast<std::size_t>(b.parent);
      xp = data.xbody[p].apply(b.pos_in_parent);
      xq = data.xquat[p] * b.quat_in_parent * joint_rotation(b, data.qpos);
    }
    xq.normalize();
    data.xquat[i] = xq;
    data.xbody[i].pos = xp;
    data.xbody[i].rot = xq.toRotationMatrix();
    data.xcom[i] = data.xbody[i].apply(b.com);
  }
  for (std::size_t g = 0; g < static_cast<std::size_t>(model.ngeom); ++g) {
    const Geom& geom = model.geoms[g];
    const Pose& x = data.xbody[static_cast<std::size_t>(geom.body)];
    data.xgeom[g].pos = x.apply(geom.local.pos);
    data.xgeom[g].rot = x.rot * geom.local.rot;
  }

  data.origin = data.xbody[0].pos;
  for (std::size_t i = 0; i < nbody; ++i) {
    const Body& b = model.bodies[i];
    const Mat3& r = data.xbody[i].rot;
    const Vec3 rel = data.xbody[i].pos - data.origin;
    const Vec3 c = data.xcom[i] - data.origin;
    data.cinert_h[i] = b.mass_kg * c;
    data.cinert_i[i] =
        r * b.inertia * r.transpose() + b.mass_kg * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());

    Vec6 v = b.parent >= 0 ? data.cvel[static_cast<std::size_t>(b.parent)] : Vec6::Zero();
    auto d = static_cast<std::size_t>(b.dof_adr);
    const auto rotation_dofs = [&](std::size_t first) {
      for (std::size_t k = 0; k < 3; ++k) {
        const Vec3 axis = r.col(static_cast<Eigen::Index>(k));
        data.cdof[first + k] = make(axis, rel.cross(axis));
      }
      // MuJoCo's order: the three rates use the velocity before this joint's
      // own rotation (equivalent: the own terms cancel in the sum).
      for (std::size_t k = 0; k < 3; ++k) data.cdof_dot[first + k] = cross_motion(v, data.cdof[first + k]);
      for (std::size_t k = 0; k < 3; ++k) v += data.cdof[first + k] * data.qvel[first + k];
    };
    switch (b.joint) {
      case JointType::free:
        for (std::size_t k = 0; k < 3; ++k) {
          data.cdof[d + k] = make(Vec3::Zero(), Vec3::Unit(static_cast<Eigen::Index>(k)));
          data.cdof_dot[d + k].setZero();
          v += data.cdof[d + k] * data.qvel[d + k];
        }
        rotation_dofs(d + 3);
        break;
      case JointType::ball: rotation_dofs(d); break;
      case JointType::hinge: {
        const Vec3 axis = r * b.hinge_axis;
        data.cdof[d] = make(axis, rel.cross(axis));
        v += data.cdof[d] * data.qvel[d];
        data.cdof_dot[d] = cross_motion(v, data.cdof[d]);
        break;
      }
      case JointType::fixed: break;
    }
    data.cvel[i] = v;
  }
}

}  // namespace tonus::sim
