// What tonus sends: the humanoid's pose as VMC's Root/Pos and Bone/Pos
// (Unity frame, unity_frame.hpp), and the gifts (virtual objects) for the
// tonus-specific /tonus/Object/Pos. docs/vmc.md lists the messages.
//
// Root and Hips follow VirtualMotionCapture's and SlimeVR's senders: the
// avatar root stays at the origin with no rotation and the Hips bone carries
// the body's position and rotation in the root's frame, so a receiver that
// ignores Root/Pos (or treats it as its avatar's placement) still places the
// body. Every other bone: its local rotation relative to its parent (the
// humanoid's joint rotation: its rest is a T-pose with every frame parallel
// to the world, as a normalised VRM's) and its rest offset from the parent.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::vmc {

// A rigid transform in Unity's frame, metres.
struct UnityTransform {
  sim::Vec3 pos_m = sim::Vec3::Zero();
  sim::Quat rot = sim::Quat::Identity();
};

struct VmcPose {
  UnityTransform root;                                 // /VMC/Ext/Root/Pos ("root")
  std::array<UnityTransform, sim::kBoneCount> bone{};  // /VMC/Ext/Bone/Pos per sim::Bone, local to the parent
};

// The pose of the humanoid (sim::build_humanoid's model: body i is sim::Bone
// i, a free root, ball, hinge or fixed joints) at `qpos` (the model's layout:
// root position, root quaternion w x y z, then each joint's coordinates).
// False, `out` untouched, when the model is not the humanoid, qpos is shorter
// than nq, or a value is not finite or a quaternion is zero. Quaternions are
// normalised. Allocates nothing, never throws.
bool pose_from_qpos(const sim::Model& humanoid, std::span<const double> qpos, VmcPose& out);

// A gift as sent: /tonus/Object/Pos (id, kind, size, Unity pose).
enum class ObjectKind : std::uint8_t { ball, cube };
const char* to_string(ObjectKind k);  // "ball", "cube"

struct VmcObject {
  int id = 0;  // stable while the object lives (the daemon's gift slot)
  ObjectKind kind = ObjectKind::ball;
  double size_m = 0.0;  // full extent: a ball's diameter, a cube's edge (Unity's primitives at this scale)
  UnityTransform pose;  // world, Unity frame
};

// An object from the internal frame (world position, rotation).
VmcObject object_to_vmc(int id, ObjectKind kind, double size_m, const sim::Vec3& pos_m, const sim::Quat& rot);

}  // namespace tonus::vmc
