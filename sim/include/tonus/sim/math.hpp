// Small fixed-size linear algebra for the physics core: Eigen's fixed types
// (never heap-allocating) under short names, and the few quaternion helpers
// the integrator and the drives need.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
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

// The shortest-arc rotation taking the direction of `from` to that of `to`
// (neither need be unit). The same arithmetic as Eigen's
// Quaternion::FromTwoVectors, bit for bit, except for opposite directions,
// where it turns by pi about an axis across `from` found in closed form:
// Eigen's version finds that axis with a JacobiSVD, whose instantiation alone
// costs every translation unit that calls it seconds of compile time.
inline Quat quat_from_two_vectors(const Vec3& from, const Vec3& to) {
  const Vec3 v0 = from.normalized();
  const Vec3 v1 = to.normalized();
  double c = v1.dot(v0);
  Quat q;
  if (c < -1.0 + 1e-12) {  // opposite: any axis across both turns one onto the other
    c = std::max(c, -1.0);
    const Vec3 mid = v0 - v1;  // along v0 (v1 is nearly -v0): any axis across it will do
    const Vec3 other = std::abs(mid.x()) < std::abs(mid.y())
                           ? (std::abs(mid.x()) < std::abs(mid.z()) ? Vec3::UnitX() : Vec3::UnitZ())
                           : (std::abs(mid.y()) < std::abs(mid.z()) ? Vec3::UnitY() : Vec3::UnitZ());
    const Vec3 axis = mid.cross(other).normalized();
    const double w2 = (1.0 + c) * 0.5;
    q.w() = std::sqrt(w2);
    q.vec() = axis * std::sqrt(1.0 - w2);
    return q;
  }
  const Vec3 axis = v0.cross(v1);
  const double s = std::sqrt((1.0 + c) * 2.0);
  q.vec() = axis * (1.0 / s);
  q.w() = s * 0.5;
  return q;
}

inline bool all_finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace tonus::sim
