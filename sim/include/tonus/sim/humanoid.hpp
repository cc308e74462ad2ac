// The humanoid: 21 bodies named as Unity's HumanBodyBones (Hips the free
// root, 20 joints), built from a skeleton (bone offsets) plus body height and
// mass, with de Leva (1996) segment parameters, capsule/sphere/box collision
// shapes, human ranges of motion and default drive gains. docs/humanoid.md
// gives the sources of every number.
//
// Frame: Z up, the body faces +X, its left is +Y. Body frames are parallel to
// the world at rest, so the rest pose is the skeleton's pose (a T-pose for the
// default skeleton) and a ball joint's quaternion is the bone's rotation from
// it. Body i is Bone i (sim/human_bones.hpp), so arrays indexed by Bone index bodies.
#pragma once

#include <array>
#include <optional>

#include "tonus/sim/anthropometry.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/model_builder.hpp"

namespace tonus::sim {

struct HumanoidSpec {
  double height_m = 1.70;
  double mass_kg = 65.0;
  Sex sex = Sex::male;
  // Bone offsets at rest, each from its parent's joint, world axes, metres;
  // the Hips entry is the root's position (feet on z = 0 for the default).
  // Absent: the default T-pose skeleton scaled to height_m (Winter's
  // segment-length proportions).
  std::optional<std::array<Vec3, kBoneCount>> bone_offsets;
  bool joint_limits = true;
  double drive_frequency_hz = 4.0;   // default gains: this natural frequency per joint ...
  double drive_damping_ratio = 1.0;  // ... critically damped
  Material material;                 // of every body shape
};

// The default skeleton for a height (the one build_humanoid uses without offsets).
std::array<Vec3, kBoneCount> default_skeleton(double height_m);

// The bodies and geoms in a builder, so callers can set options (ground,
// solver, features) or add bodies before build(). A bad spec (height, mass,
// skeleton) leaves `error` non-empty; build() then refuses too.
ModelBuilder humanoid_builder(const HumanoidSpec& spec, std::string& error);

// humanoid_builder(spec).build() with the default options.
BuildResult build_humanoid(const HumanoidSpec& spec);

}  // namespace tonus::sim
