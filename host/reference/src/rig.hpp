// What the retargeting needs to know of the humanoid model, resolved once:
// each bone's rest direction, its left axis and its length, in the body's own
// frame, and the leg length that scales the clip.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference::detail {

using sim::Bone;
using sim::Quat;
using sim::Vec3;

struct Rig {
  const sim::Model* model = nullptr;
  std::array<Vec3, sim::kBoneCount> dir{};         // unit, towards the chain child (end bones: the twist axis)
  std::array<double, sim::kBoneCount> length{};    // joint to the chain child's joint, m (0 for end bones)
  std::array<Vec3, sim::kBoneCount> lateral{};     // unit, the rest pose's left (hip to hip)
  std::array<Quat, sim::kBoneCount> rest_world{};  // body frames at zero joint rotations
  Vec3 hip_mid = Vec3::Zero();                     // midpoint of the hip joints, Hips frame
  double leg_m = 0.0;                              // hip to ankle joint, mean of both legs

  [[nodiscard]] const sim::Body& body(Bone b) const { return model->bodies[sim::index(b)]; }
};

// The bone whose joint the segment of `b` ends at (the next bone down the
// chain); none for the end bones (head, hands, toes).
std::optional<Bone> chain_child(Bone b);

// Checks that the model is sim/humanoid.hpp's (21 bodies in Bone order,
// named and connected as HumanBodyBones, a free Hips, hinged elbows, knees
// and toes, ball joints elsewhere) and fills `rig`. Empty on success, else
// what is wrong.
std::string make_rig(const sim::Model& model, Rig& rig);

}  // namespace tonus::reference::detail
