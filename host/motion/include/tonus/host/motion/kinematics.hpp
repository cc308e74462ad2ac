// Forward kinematics of a clip, in the file's own frame and units.
//
// Conventions (the usual BVH ones):
// - A joint's local transform maps its own frame into its parent's:
//   x_parent = R_local * x_joint + t_local.
// - t_local is the OFFSET, with each position channel present replacing its
//   component: position channels are the joint's translation from its
//   parent, not an increment on the OFFSET. This is what the CMU files (root
//   OFFSET zero, root position channels absolute) and the Bandai Namco files
//   (position channels on every joint, equal to its OFFSET) both assume.
// - R_local is the product of the rotation channels in the order the joint
//   lists them, angles in degrees: "Zrotation Xrotation Yrotation" gives
//   R = Rz * Rx * Ry (column vectors). Position and rotation channels may be
//   interleaved; only their relative order among rotations matters.
// - Global: R_j = R_parent * R_local, p_j = p_parent + R_parent * t_local; the
//   root's parent is the file's frame. An End Site gets its parent's
//   rotation and sits at its OFFSET in the parent's frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

#include "tonus/host/motion/clip.hpp"
#include "tonus/host/motion/euler.hpp"

namespace tonus::motion {

struct JointPose {
  Eigen::Quaterniond local_rotation = Eigen::Quaterniond::Identity();  // relative to the parent
  Eigen::Vector3d local_translation = Eigen::Vector3d::Zero();         // in the parent's frame
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();        // in the file's frame
  Eigen::Vector3d position = Eigen::Vector3d::Zero();                  // in the file's frame and units
};

// Every joint's pose at `frame`, one entry per joint (End Sites included) in
// the clip's order. `out` is resized, so a reused vector costs no allocation.
// False (and `out` empty) if frame is not a frame of the clip with a row of
// values, or a joint's parent is not an earlier joint. Allocation-free once
// `out` has the capacity.
bool forward_kinematics(const Clip& clip, std::size_t frame, std::vector<JointPose>& out);
// The same, returning the poses; empty on failure.
[[nodiscard]] std::vector<JointPose> forward_kinematics(const Clip& clip, std::size_t frame);

// One joint's local rotation or translation at `frame`, without running the
// whole chain; nothing where forward_kinematics would fail or joint is out
// of range.
[[nodiscard]] std::optional<Eigen::Quaterniond> local_rotation(const Clip& clip, std::size_t frame, std::size_t joint);
[[nodiscard]] std::optional<Eigen::Vector3d> local_translation(const Clip& clip, std::size_t frame, std::size_t joint);

// The Euler order of a joint's rotation channels if it has exactly three,
// about three distinct axes; nothing otherwise (End Sites, 1- or 2-axis joints).
[[nodiscard]] std::optional<EulerOrder> rotation_order(const Joint& joint);

// Writes rotation q into the joint's own rotation channels at `frame`, as the
// angles closest to the ones there now (euler_from_quaternion_near), so the
// channels stay continuous. False, and nothing written, if the joint has no
// rotation_order, frame or joint is out of range, or q is zero or not finite.
bool set_local_rotation(Clip& clip, std::size_t frame, std::size_t joint, const Eigen::Quaterniond& q);

// Re-expresses the joint's rotation at every frame after `from_frame` as the
// angles nearest the previous frame's as this pass leaves them
// (euler_from_quaternion_near): no rotation changes, only its angles, so the
// channels jump only where the rotation itself does or an Euler singularity
// forces it. A frame whose angles are already the nearest (to 1e-6 degrees)
// keeps them bit for bit, as does `from_frame`. False, and nothing changed,
// if the joint has no rotation_order or from_frame or joint is out of range.
bool unwrap_rotation(Clip& clip, std::size_t joint, std::size_t from_frame);

// Writes a translation into the joint's three position channels at `frame`.
// False, and nothing written, if the joint lacks one of Xposition, Yposition,
// Zposition, frame or joint is out of range, or t is not finite.
bool set_local_translation(Clip& clip, std::size_t frame, std::size_t joint, const Eigen::Vector3d& t);

}  // namespace tonus::motion
