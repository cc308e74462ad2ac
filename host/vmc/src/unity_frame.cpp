#include "tonus/host/vmc/unity_frame.hpp"

namespace tonus::vmc {

sim::Mat3 unity_from_internal_matrix() {
  sim::Mat3 m;
  m << 0.0, -1.0, 0.0,  // Unity x (right) = -internal y (left)
      0.0, 0.0, 1.0,    // Unity y (up) = internal z
      1.0, 0.0, 0.0;    // Unity z (forward) = internal x
  return m;
}

sim::Vec3 to_unity(const sim::Vec3& p) { return {-p.y(), p.z(), p.x()}; }

// M^-1 = M^T: internal = (u.z, -u.x, u.y).
sim::Vec3 from_unity(const sim::Vec3& u) { return {u.z(), -u.x(), u.y()}; }

// Axis v -> -M v; w unchanged (the angle keeps its value, the reflection flips the sense).
sim::Quat to_unity(const sim::Quat& q) { return {q.w(), q.y(), -q.z(), -q.x()}; }

// Axis u -> -M^-1 u = (-u.z, u.x, -u.y).
sim::Quat from_unity(const sim::Quat& u) { return {u.w(), -u.z(), u.x(), -u.y()}; }

}  // namespace tonus::vmc
