// Spatial (6D) algebra in one world-aligned frame at data.origin, MuJoCo's
// layout: motion vectors (angular; linear velocity of the point at the
// origin), force vectors (torque about the origin; force). Private to sim/.
#pragma once

#include "tonus/sim/math.hpp"

namespace tonus::sim::spatial {

inline Vec3 ang(const Vec6& v) { return v.head<3>(); }
inline Vec3 lin(const Vec6& v) { return v.tail<3>(); }

inline Vec6 make(const Vec3& angular, const Vec3& linear) {
  Vec6 v;
  v << angular, linear;
  return v;
}

// Motion cross product: the rate of change of motion vector m carried by velocity v.
inline Vec6 cross_motion(const Vec6& v, const Vec6& m) {
  return make(ang(v).cross(ang(m)), ang(v).cross(lin(m)) + lin(v).cross(ang(m)));
}

// Force cross product (the dual): v x* f.
inline Vec6 cross_force(const Vec6& v, const Vec6& f) {
  return make(ang(v).cross(ang(f)) + lin(v).cross(lin(f)), ang(v).cross(lin(f)));
}

// Spatial inertia about the origin, kept as (mass, first moment h = m*c,
// rotational inertia about the origin): cheap to add, cheap to apply.
struct Inertia {
  double m = 0.0;
  Vec3 h = Vec3::Zero();
  Mat3 i = Mat3::Zero();

  [[nodiscard]] Vec6 apply(const Vec6& v) const {
    return make(i * ang(v) + h.cross(lin(v)), m * lin(v) - h.cross(ang(v)));
  }
};

// The velocity of the world point p for a body moving with spatial velocity v.
inline Vec3 point_velocity(const Vec6& v, const Vec3& p_minus_origin) { return lin(v) + ang(v).cross(p_minus_origin); }

}  // namespace tonus::sim::spatial
