// Shared fixtures of the avatar tests: the humanoid, controllers, reference poses, independent measures.
#pragma once

#include <array>
#include <span>

#include "tonus/host/avatar/controller.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::avatar::test {

// The default humanoid (sim::build_humanoid(HumanoidSpec{})), built once.
const sim::Model& humanoid();

// A controller on the default humanoid; fails the test when create() refuses.
AvatarController make_controller(const AvatarConfig& config = {});

// A ball joint's quaternion (rotation from the rest pose, w x y z) or a hinge's angle.
void set_ball(ReferencePose& ref, sim::Bone bone, const sim::Quat& q);
void set_hinge(ReferencePose& ref, sim::Bone bone, double angle_rad);

// The rest T-pose with both upper arms lowered by `lower_rad` (about the
// forward axis) and both elbows bent by `elbow_rad` (flexion), at rest.
ReferencePose arms_lowered(double lower_rad, double elbow_rad);

// World position of a bone's centre of mass in a configuration (forward
// kinematics on a scratch Data), and in a tick's output bone frames.
sim::Vec3 com_of(std::span<const double> qpos, sim::Bone bone);
sim::Vec3 com_of(const TickOutput& out, sim::Bone bone);

// The norm of a joint's torque over its dofs.
double joint_norm(std::span<const double> tau, int body);

// Largest joint |tau| relative to the joint's torque limit (1 = at the limit).
double worst_limit_ratio(std::span<const double> tau);

// Every array of the output finite.
bool all_finite(const TickOutput& out);

}  // namespace tonus::avatar::test
