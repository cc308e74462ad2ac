#include "tonus/host/vmc/pose_out.hpp"

#include <cmath>

#include "tonus/host/vmc/unity_frame.hpp"

namespace tonus::vmc {

namespace {

bool is_humanoid(const sim::Model& m) {
  if (m.nbody < static_cast<int>(sim::kBoneCount) || m.bodies[0].joint != sim::JointType::free) return false;
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    const sim::Body& b = m.bodies[i];
    if (b.name_view() != sim::kBones[i].name) return false;
    const std::optional<sim::Bone> parent = sim::kBones[i].parent;
    if (b.parent != (parent ? static_cast<int>(sim::index(*parent)) : -1)) return false;
    if (i > 0 && b.joint == sim::JointType::free) return false;
  }
  return true;
}

// A quaternion stored w x y z at q; false when not finite or (near) zero.
bool read_quat(const double* q, sim::Quat& out) {
  const sim::Quat r(q[0], q[1], q[2], q[3]);
  const double n = r.norm();
  if (!std::isfinite(n) || n < 1e-9) return false;
  out = sim::Quat(r.coeffs() / n);
  return true;
}

}  // namespace

bool pose_from_qpos(const sim::Model& humanoid, std::span<const double> qpos, VmcPose& out) {
  if (!is_humanoid(humanoid) || qpos.size() < static_cast<std::size_t>(humanoid.nq)) return false;
  // Local rotations first, into a scratch pose, so a bad value leaves `out` untouched.
  std::array<sim::Quat, sim::kBoneCount> local{};
  sim::Vec3 root_pos = sim::Vec3::Zero();
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
    const sim::Body& b = humanoid.bodies[i];
    const double* q = qpos.data() + b.qpos_adr;
    sim::Quat joint = sim::Quat::Identity();
    switch (b.joint) {
      case sim::JointType::free:
        root_pos = sim::Vec3(q[0], q[1], q[2]);
        if (!sim::all_finite(root_pos) || !read_quat(q + 3, joint)) return false;
        break;
      case sim::JointType::ball:
        if (!read_quat(q, joint)) return false;
        break;
      case sim::JointType::hinge:
        if (!std::isfinite(q[0])) return false;
        joint = sim::Quat(Eigen::AngleAxisd(q[0], b.hinge_axis));
        break;
      case sim::JointType::fixed: break;
    }
    // The body's frame relative to its parent's: the rest turn, then the joint's.
    local[i] = (b.quat_in_parent * joint).normalized();
  }
  out.root = UnityTransform{};
  out.bone[0] = {to_unity(root_pos), to_unity(local[0])};
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    out.bone[i] = {to_unity(humanoid.bodies[i].pos_in_parent), to_unity(local[i])};
  }
  return true;
}

const char* to_string(ObjectKind k) { return k == ObjectKind::cube ? "cube" : "ball"; }

VmcObject object_to_vmc(int id, ObjectKind kind, double size_m, const sim::Vec3& pos_m, const sim::Quat& rot) {
  return {id, kind, size_m, {to_unity(pos_m), to_unity(rot.normalized())}};
}

}  // namespace tonus::vmc
