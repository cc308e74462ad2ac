#include "rig.hpp"

namespace tonus::reference::detail {
namespace {

sim::JointType expected_joint(Bone b) {
  switch (b) {
    case Bone::Hips: return sim::JointType::free;
    case Bone::LeftLowerArm:
    case Bone::RightLowerArm:
    case Bone::LeftLowerLeg:
    case Bone::RightLowerLeg:
    case Bone::LeftToes:
    case Bone::RightToes: return sim::JointType::hinge;
    default: return sim::JointType::ball;
  }
}

}  // namespace

std::optional<Bone> chain_child(Bone b) {
  const std::size_t next = sim::index(b) + 1;
  if (next >= sim::kBoneCount || sim::kBones[next].parent != b) return std::nullopt;
  return sim::kBones[next].bone;
}

std::string make_rig(const sim::Model& m, Rig& rig) {
  if (m.nbody < static_cast<int>(sim::kBoneCount)) {
    return "the model has " + std::to_string(m.nbody) + " bodies; the humanoid has " + std::to_string(sim::kBoneCount);
  }
  rig.model = &m;
  for (const sim::BoneInfo& info : sim::kBones) {
    const std::size_t i = sim::index(info.bone);
    const sim::Body& b = m.bodies[i];
    const int parent = info.parent ? static_cast<int>(sim::index(*info.parent)) : -1;
    if (b.name_view() != info.name || b.parent != parent) {
      return "body " + std::to_string(i) + " is '" + std::string(b.name_view()) + "'; the humanoid's is " +
             std::string(info.name) + " under " + (info.parent ? std::string(sim::name(*info.parent)) : "the world");
    }
    if (b.joint != expected_joint(info.bone)) {
      return "body " + std::string(info.name) + " has another joint type than the humanoid's";
    }
    rig.rest_world[i] = parent < 0 ? Quat::Identity()  // a free root's rotation is its qpos quaternion
                                   : Quat(rig.rest_world[static_cast<std::size_t>(parent)] * b.quat_in_parent);
    const auto child = chain_child(info.bone);
    const Vec3 seg = child ? m.bodies[sim::index(*child)].pos_in_parent : b.limit.twist_axis;
    if (seg.norm() < 1e-6) return "body " + std::string(info.name) + " has no rest direction";
    rig.dir[i] = seg.normalized();
    rig.length[i] = child ? seg.norm() : 0.0;
  }
  const Vec3 left_hip = rig.body(Bone::LeftUpperLeg).pos_in_parent;
  const Vec3 right_hip = rig.body(Bone::RightUpperLeg).pos_in_parent;
  if ((left_hip - right_hip).norm() < 1e-6) return "the humanoid's hip joints coincide";
  rig.hip_mid = 0.5 * (left_hip + right_hip);
  const Vec3 left_world = (left_hip - right_hip).normalized();  // the root's rest rotation is the identity
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) rig.lateral[i] = rig.rest_world[i].conjugate() * left_world;
  const auto leg = [&](Bone thigh) { return rig.length[sim::index(thigh)] + rig.length[sim::index(thigh) + 1]; };
  rig.leg_m = 0.5 * (leg(Bone::LeftUpperLeg) + leg(Bone::RightUpperLeg));
  return {};
}

}  // namespace tonus::reference::detail
