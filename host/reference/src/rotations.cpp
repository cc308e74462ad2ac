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
  return (sim::quat_from_two_vectors(now, d) * from).normalized();
}

double angle_about(const Vec3& axis, const Vec3& v0, const Vec3& v) {
  Vec3 a, b;
  if (!orthonormal(v0, axis, a) || !orthonormal(v, axis, b)) return 0.0;
  return std::atan2(axis.dot(a.cross(b)), a.dot(b));
}

void keep_hemisphere(const sim::Model& m, std::span<double> qpos, std::span<const double> previous) {
  for (int i = 0; i < m.nbody; ++i) {
    const sim::Body& b = m.bodies[static_cast<std::size_t>(i)];
    if (b.joint != sim::JointType::ball && b.joint != sim::JointType::free) continue;
    const std::size_t a = static_cast<std::size_t>(b.qpos_adr) + (b.joint == sim::JointType::free ? 3 : 0);
    double dot = 0.0;
    for (std::size_t k = 0; k < 4; ++k) dot += qpos[a + k] * previous[a + k];
    if (dot < 0.0) {
      for (std::size_t k = 0; k < 4; ++k) qpos[a + k] = -qpos[a + k];
    }
  }
}

}  // namespace tonus::reference::detail
