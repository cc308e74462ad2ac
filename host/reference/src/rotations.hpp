// Rotation helpers of the retargeting: a frame fixed by one exact and one
// approximate direction, the least rotation that aims a bone, and the signed
// angle a hinge needs. Clamping into the joint ranges is sim's
// (tonus/sim/joint_limits.hpp).
#pragma once

#include <span>

#include "tonus/sim/model.hpp"

namespace tonus::reference::detail {

using sim::Quat;
using sim::Vec3;

// Below this length a direction is treated as undefined.
inline constexpr double kTiny = 1e-9;

// The rotation W with W * r == d (both made unit) and W * s as close to `a`
// as that allows (s and a taken orthogonal to r and d). False, and W
// untouched, when a lies along d or s along r.
bool frame_match(const Vec3& r, const Vec3& s, const Vec3& d, const Vec3& a, Quat& w);

// `from` turned by the least rotation that takes from * r onto d.
Quat aim(const Quat& from, const Vec3& r, const Vec3& d);

// The angle about `axis` (unit) that turns v0 closest to v (both projected on
// the plane normal to the axis); 0 when either projection vanishes.
double angle_about(const Vec3& axis, const Vec3& v0, const Vec3& v);

// Each quaternion of `qpos` (the free root's rotation, every ball joint's)
// negated where needed into the hemisphere of the same one in `previous`, so
// a tracker interpolating them never turns the long way.
void keep_hemisphere(const sim::Model& m, std::span<double> qpos, std::span<const double> previous);

}  // namespace tonus::reference::detail
