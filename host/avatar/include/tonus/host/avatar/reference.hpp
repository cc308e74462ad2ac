// The reference pose of one tick, in the humanoid model's layout: the root's
// pose and every joint's rotation (qpos), with velocities (qvel) when the
// source has them. Plain fixed-size arrays, so a tick copies without
// allocating.
#pragma once

#include <array>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::avatar {

struct ReferencePose {
  // Root position (3, world) + quaternion (4, w x y z), then the joints
  // (ball: quaternion, hinge: angle), as sim::Model's qpos.
  std::array<double, sim::kMaxQpos> qpos{};
  // Root linear velocity (world) + angular velocity (root frame), then the
  // joints' (ball: body-frame angular velocity, hinge: rate), as qvel.
  std::array<double, sim::kMaxDofs> qvel{};
  // False: the controller differentiates consecutive references itself.
  bool has_velocity = false;
};

// The model's rest pose, at rest.
ReferencePose rest_reference(const sim::Model& model);

}  // namespace tonus::avatar
