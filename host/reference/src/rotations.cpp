#include "rotations.hpp"

#include <algorithm>
#include <cmath>

namespace tonus::reference::detail {
namespace {

// The part of v orthogonal to the unit vector n, made unit; false when too short.
bool orthonormal(const Vec3& v, const Vec3& n, Vec3& out) {
  const Vec3 p = v - v.dot(n) * n;
  const double len = p.norm();
  if (len < 1e-6 * std::max(1.0, v.norm())) return false;
  out = p / len;
  return true;
}

}  // namespace

bool frame_match(const Vec3& r, const Vec3& s, const Vec3& d, const Vec3& a, Quat& w) {
  if (r.norm() < kTiny || d.norm() < kTiny) return false;
  const Vec3 r1 = r.normalized(), d1 = d.normalized();
  Vec3 s1, a1;
  if (!orthonormal(s, r1, s1) || !orthonormal(a, d1, a1)) return false;
  sim::Mat3 body, world;
  body << r1, s1, r1.cross(s1);
  world << d1, a1, d1.cross(a1);
  w = Quat(sim::Mat3(world * body.transpose())).normalized();
  return true;
}

Quat aim(const Quat& from, const Vec3& r, const Vec3& d) {
  const Vec3 now = from * r;
  if (now.norm() < kTiny || d.norm() < kTiny) return from;
  return (Quat::FromTwoVectors(now, d) * from).normalized();
}

double angle_about(const Vec3& axis, const Vec3& v0, const Vec3& v) {
  Vec3 a, b;
  if (!orthonormal(v0, axis, a) || !orthonormal(v, axis, b)) return 0.0;
  return std::atan2(axis.dot(a.cross(b)), a.dot(b));
}

double twist_about(const Quat& q_in, const Vec3& t) {
  Quat q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return 2.0 * std::atan2(q.vec().dot(t), q.w());
}

bool clamp_ball(Quat& q, const sim::JointLimit& limit) {
  if (!limit.enabled) return false;
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vec3 t = limit.twist_axis.normalized();
  // Twist: the rotation about t that q contains; swing: the rest, about an axis normal to t.
  const double twist = twist_about(q, t);
  const Quat twist_q(Eigen::AngleAxisd(twist, t));
  const Quat swing_q = q * twist_q.conjugate();
  const double swing_sin = swing_q.vec().norm();
  const double swing = 2.0 * std::atan2(swing_sin, std::abs(swing_q.w()));
  const double new_twist = std::clamp(twist, limit.lower_rad, limit.upper_rad);
  const double new_swing = std::min(swing, limit.swing_max_rad);
  if (new_twist == twist && new_swing == swing) return false;
  Quat new_swing_q = swing_q;
  if (new_swing != swing && swing_sin > kTiny) {
    const Vec3 axis = (swing_q.w() < 0.0 ? -1.0 : 1.0) * swing_q.vec() / swing_sin;
    new_swing_q = Quat(Eigen::AngleAxisd(new_swing, axis));
  }
  q = (new_swing_q * Quat(Eigen::AngleAxisd(new_twist, t))).normalized();
  return true;
}

bool clamp_hinge(double& angle_rad, const sim::JointLimit& limit) {
  if (!limit.enabled) return false;
  const double c = std::clamp(angle_rad, limit.lower_rad, limit.upper_rad);
  if (c == angle_rad) return false;
  angle_rad = c;
  return true;
}

}  // namespace tonus::reference::detail
