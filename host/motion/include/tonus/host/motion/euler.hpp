// Euler angles in BVH's convention and quaternions.
//
// An order names the rotation channels as a joint lists them: zyx is
// "Zrotation Yrotation Xrotation" and means R = Rz(a0) * Ry(a1) * Rx(a2)
// acting on column vectors (a0 applied last, about the parent-side axis).
// Angles are in degrees and in the order's own axis order. Rotations are
// right-handed: Rz(90) takes +x to +y.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>

namespace tonus::motion {

enum class Axis : std::uint8_t { x, y, z };

// The six orders of three distinct axes (Tait-Bryan angles).
enum class EulerOrder : std::uint8_t { xyz, xzy, yxz, yzx, zxy, zyx };

using EulerAngles = std::array<double, 3>;  // degrees, in the order's axis order

[[nodiscard]] std::array<Axis, 3> axes(EulerOrder order);
// The order of three axes; nothing if two are the same.
[[nodiscard]] std::optional<EulerOrder> euler_order(Axis first, Axis second, Axis third);

// R = R_first(a[0]) * R_second(a[1]) * R_third(a[2]).
[[nodiscard]] Eigen::Quaterniond quaternion_from_euler(EulerOrder order, const EulerAngles& degrees);

// The angles of q (normalised first; q and -q give the same angles): the
// first and third in (-180, 180], the middle in [-90, 90]. At gimbal lock
// (middle angle +-90) the first is chosen from q's components and the third
// takes the rest, so the result always rebuilds q to rounding. A zero or
// non-finite q gives NaN angles.
[[nodiscard]] EulerAngles euler_from_quaternion(const Eigen::Quaterniond& q, EulerOrder order);

// The angles of q closest to `reference` (e.g. the previous frame's angles):
// of the two angle triples giving q, (a, b, c) and (a + 180, 180 - b, c + 180),
// and, at gimbal lock, the triple keeping the reference's first angle, each
// shifted by whole turns to the reference, the one with the smallest squared
// distance. Keeps written channels free of 360-degree jumps and gimbal flips.
// Reference angles that are not finite or beyond +-1e6 degrees are ignored
// (the principal angle is kept).
[[nodiscard]] EulerAngles euler_from_quaternion_near(const Eigen::Quaterniond& q, EulerOrder order,
                                                     const EulerAngles& reference);

}  // namespace tonus::motion
