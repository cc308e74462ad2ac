// The internal frame and Unity's (the frame every VMC message is in).
//
// Internal: right-handed, Z up, metres; the humanoid faces +X, its left is +Y
// (sim/humanoid.hpp). Unity: left-handed, Y up, metres; an avatar faces +Z,
// its right is +X. So forward x -> Unity z, left y -> Unity -x, up z -> Unity
// y: a point maps by the matrix M with unity = M p = (-y, z, x). det M = -1
// (a reflection: the handedness changes), so a rotation, whose axis is an
// axial vector, maps as R_u = M R M^-1 with axis -M v: the quaternion
// (w, v) becomes (w, -M v) = (w, y, -z, -x). docs/vmc.md derives it; the tests
// check it against the rotation matrices, not against itself.
#pragma once

#include "tonus/sim/math.hpp"

namespace tonus::vmc {

// M: internal axes to Unity's (rows: Unity x, y, z in internal coordinates).
sim::Mat3 unity_from_internal_matrix();

sim::Vec3 to_unity(const sim::Vec3& p);
sim::Vec3 from_unity(const sim::Vec3& u);
sim::Quat to_unity(const sim::Quat& q);
sim::Quat from_unity(const sim::Quat& u);

}  // namespace tonus::vmc
