// Narrow phase: the contact points between two posed shapes.
//
// Every pair of {sphere, capsule, box, plane} except plane-plane is handled,
// in either order. Points are reported while the shapes are still apart by up
// to `margin_m` (speculative contacts: the solver then lets the gap close in
// one step but not overshoot, which is what keeps a 10 m/s ball from
// tunnelling at dt = 1 ms). Pure functions: no allocation, no state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/sim/geometry.hpp"

namespace tonus::sim {

struct ContactPoint {
  Vec3 pos = Vec3::Zero();      // world, midway between the two surfaces
  Vec3 normal = Vec3::UnitZ();  // world, unit, pointing from shape b towards shape a
  double dist_m = 0.0;          // signed gap along the normal: > 0 apart, < 0 penetrating
};

// Most points any pair produces (a box face on a box face is reduced to 4).
inline constexpr std::size_t kMaxPointsPerPair = 4;

// Writes up to min(out.size(), kMaxPointsPerPair) points whose gap is at most
// margin_m and returns how many. Degenerate or non-finite input gives 0.
std::size_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b, double margin_m,
                    std::span<ContactPoint> out);

}  // namespace tonus::sim
