// Small fixed-size linear algebra for the physics core: Eigen's fixed types
// (never heap-allocating) under short names, and the few quaternion helpers
// the integrator and the drives need.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace tonus::sim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;  // unit quaternions; MuJoCo stores (w, x, y, z), Eigen (x, y, z, w)
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// A rigid transform, world from local: x_world = rot * x_local + pos.
struct Pose {
  Vec3 pos = Vec3::Zero();
  Mat3 rot = Mat3::Identity();

  [[nodiscard]] Vec3 apply(const Vec3& local) const { return rot * local + pos; }
  [[nodiscard]] Vec3 inverse_apply(const Vec3& world) const { return rot.transpose() * (world - pos); }
};

// Skew-symmetric matrix [v]x, so that skew(v) * w == v.cross(w).
inline Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// exp map: the unit quaternion of a rotation vector (axis * angle).
inline Quat quat_exp(const Vec3& rotvec) {
  const double angle = rotvec.norm();
  if (angle < 1e-12) {
    return Quat(1.0, 0.5 * rotvec.x(), 0.5 * rotvec.y(), 0.5 * rotvec.z()).normalized();
  }
  const double s = std::sin(0.5 * angle) / angle;
  return {std::cos(0.5 * angle), s * rotvec.x(), s * rotvec.y(), s * rotvec.z()};
}

// log map: the rotation vector of a unit quaternion, angle in [0, pi] (the
// short way round: q and -q give the same rotation vector).
inline Vec3 quat_log(const Quat& q) {
  double w = q.w();
  Vec3 v = q.vec();
  if (w < 0.0) {
    w = -w;
    v = -v;
  }
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;
  return (2.0 * std::atan2(s, w) / s) * v;
}

// The rotation vector taking a to b in a's frame (the short way round).
inline Vec3 quat_between(const Quat& a, const Quat& b) { return quat_log((a.conjugate() * b).normalized()); }

// Right-multiplied integration, as MuJoCo's mju_quatIntegrate: the angular
// velocity is expressed in the rotating (local) frame.
inline Quat quat_integrate(const Quat& q, const Vec3& omega_local, double dt_s) {
  return (q * quat_exp(omega_local * dt_s)).normalized();
}

inline bool all_finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace tonus::sim
