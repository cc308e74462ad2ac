#include "two_bone.hpp"

#include <algorithm>
#include <cmath>

#include "rotations.hpp"

namespace tonus::reference::detail {
namespace {

// The part of v across the unit direction d, made unit; false when too short.
bool across(const sim::Vec3& v, const sim::Vec3& d, sim::Vec3& out) {
  const sim::Vec3 p = v - v.dot(d) * d;
  const double n = p.norm();
  if (n < 1e-6) return false;
  out = p / n;
  return true;
}

}  // namespace

MiddleJoint place_middle_joint(const sim::Vec3& root, const sim::Vec3& dir, double dist, double a, double b,
                               const sim::Vec3& pole, const sim::Vec3& fallback_pole) {
  MiddleJoint m;
  if (!across(pole, dir, m.side) && !across(fallback_pole, dir, m.side)) {
    const sim::Vec3 any = std::abs(dir.x()) < 0.9 ? sim::Vec3::UnitX() : sim::Vec3::UnitY();
    across(any, dir, m.side);
  }
  const double cos_a = std::clamp((a * a + dist * dist - b * b) / (2.0 * a * dist), -1.0, 1.0);
  const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
  m.pos = root + a * (cos_a * dir + sin_a * m.side);
  return m;
}

TwoBoneSolution solve_two_bone(const TwoBoneLimb& limb, const sim::Vec3& root, const sim::Vec3& target,
                               const sim::Vec3& pole, const sim::Vec3& fallback_pole) {
  TwoBoneSolution s;
  const double a = limb.upper_m, b = limb.lower_m;
  const sim::Vec3 d = target - root;
  double dist = d.norm();
  sim::Vec3 dir;
  if (dist < 1e-9) {
    dir = fallback_pole.norm() > 1e-9 ? sim::Vec3(-fallback_pole.normalized()) : sim::Vec3(-sim::Vec3::UnitZ());
  } else {
    dir = d / dist;
  }
  const double shortest = std::abs(a - b) + 1e-9, longest = a + b;
  if (limb.soft_m > 0.0 && dist > longest - limb.soft_m) {
    dist = longest - limb.soft_m * std::exp(-(dist - (longest - limb.soft_m)) / limb.soft_m);
  }
  dist = std::clamp(dist, shortest, longest);

  const MiddleJoint middle = place_middle_joint(root, dir, dist, a, b, pole, fallback_pole);
  const sim::Vec3 end = root + dist * dir;
  const sim::Vec3 u = (middle.pos - root) / a;
  const sim::Vec3 f = (end - middle.pos) / b;
  const sim::Vec3 n = middle.side.cross(dir);  // the hinge axis in the world for a positive bend
  if (!frame_match(limb.upper_dir, limb.hinge, u, n, s.upper)) {
    s.upper = sim::quat_from_two_vectors(limb.upper_dir, u);
  }
  s.hinge_rad = angle_about(limb.hinge, limb.lower_dir, s.upper.conjugate() * f);
  return s;
}

}  // namespace tonus::reference::detail
