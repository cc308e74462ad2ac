// Collision shapes. Each is described in its own local frame; a Pose places
// it in the world. Conventions follow MuJoCo's geoms so the MJCF export is a
// one-to-one copy: a capsule's segment lies along local z, a box is given by
// its half extents, a plane is z = 0 of its frame with +z as its normal.
#pragma once

#include <cstdint>

#include "tonus/sim/math.hpp"

namespace tonus::sim {

enum class ShapeType : std::uint8_t { sphere, capsule, box, plane };

struct Shape {
  ShapeType type = ShapeType::sphere;
  double radius_m = 0.0;               // sphere, capsule
  double half_length_m = 0.0;          // capsule: half the length of its core segment (along local z)
  Vec3 half_extents_m = Vec3::Zero();  // box

  static Shape sphere(double r) { return {ShapeType::sphere, r, 0.0, Vec3::Zero()}; }
  static Shape capsule(double r, double half_len) { return {ShapeType::capsule, r, half_len, Vec3::Zero()}; }
  static Shape box(const Vec3& half) { return {ShapeType::box, 0.0, 0.0, half}; }
  static Shape plane() { return {ShapeType::plane, 0.0, 0.0, Vec3::Zero()}; }
};

// Radius of a sphere centred on the shape's origin that contains it
// (infinite for a plane). Broad phase and speculative margins use it.
double bounding_radius(const Shape& s);

// True when the shape's sizes are finite and positive (a plane has none).
bool shape_is_valid(const Shape& s);

}  // namespace tonus::sim
