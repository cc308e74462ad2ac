// Viewers' gifts: virtual objects that live in simulation B only. A ball
// thrown at a bone, a cube dropped above a bone; each with a lifetime. A gift
// is named by its GiftId (the physics slot and its generation, so an id kept
// after the gift is gone never reaches a newer one).
#pragma once

#include <cstdint>
#include <string_view>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::avatar {

struct GiftId {
  int slot = -1;
  std::uint32_t generation = 0;
  [[nodiscard]] bool valid() const { return slot >= 0; }
  friend bool operator==(const GiftId&, const GiftId&) = default;
};

// A ball thrown so that its flight (gravity included) reaches the bone's
// centre `distance_m` away after distance_m / speed_mps seconds.
struct ThrowBall {
  sim::Bone target = sim::Bone::Chest;
  double mass_kg = 0.45;  // a size-5 football
  double radius_m = 0.11;
  double speed_mps = 8.0;
  // Direction of travel, world; zero: from straight ahead of the avatar's
  // root (the body faces its root's +X, so the ball travels along -X).
  sim::Vec3 direction = sim::Vec3::Zero();
  double distance_m = 1.5;   // where it starts, from the target
  double restitution = 0.5;  // a football on a body
  double friction = 0.6;
  double lifetime_s = 5.0;  // removed after this (0: never)
};

// A cube released at rest with its bottom `height_m` above the top of the
// bone's shape.
struct DropCube {
  sim::Bone target = sim::Bone::RightHand;
  double mass_kg = 1.0;
  double edge_m = 0.08;
  double height_m = 0.3;
  double friction = 0.8;
  double lifetime_s = 0.0;  // 0: stays until removed
};

enum class GiftError : std::uint8_t {
  none,
  full,        // every object slot is taken: refused, nothing dropped
  bad_target,  // a bone the model has no shape for
  bad_params,  // non-finite, non-positive or absurd mass, size, speed, height or lifetime
  not_found,   // remove(): no such gift (already gone)
};
std::string_view to_string(GiftError e);

struct SpawnResult {
  GiftId id;
  GiftError error = GiftError::none;
  [[nodiscard]] bool ok() const { return error == GiftError::none; }
};

}  // namespace tonus::avatar
