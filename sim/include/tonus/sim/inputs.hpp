// What the caller hands the step every tick: drive targets and gains, the
// feedforward torques, and the root's reference. Plain fixed-size arrays so a
// tick copies into it without allocating; make_inputs() starts it from the
// model's rest pose and default gains.
#pragma once

#include <array>
#include <cstdint>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::sim {

struct Model;

// How the drives apply their PD law.
//  implicit: the torque is evaluated at the end-of-step velocity and position
//            (stable PD: Springhead's joint motors, PhysX drives, Tan et al. 2011),
//            so any stiffness stays stable;
//  explicit: the torque is evaluated at the start-of-step state (the textbook
//            law, kept as the baseline that diverges at high gains).
enum class DriveScheme : std::uint8_t { implicit, explicit_baseline };

// A 6-DoF PD servo pulling a free root towards its reference pose (the
// non-physical "hand of god"; its wrench is reported every step).
struct RootServo {
  bool enabled = false;
  double kp_lin = 0.0;  // N/m
  double kd_lin = 0.0;  // N*s/m
  double kp_ang = 0.0;  // N*m/rad
  double kd_ang = 0.0;  // N*m*s/rad
};

struct StepInputs {
  DriveScheme scheme = DriveScheme::implicit;

  // Drive targets in the model's qpos / qvel layout (root entries unused):
  // a quaternion (w x y z) for ball joints, an angle for hinges.
  std::array<double, kMaxQpos> target_qpos{};
  std::array<double, kMaxDofs> target_qvel{};
  // Feedforward generalized force per dof, N*m (root dofs: an external
  // force, world frame, and torque, body frame, on the root).
  std::array<double, kMaxDofs> tau_ff{};
  // Gains per dof, indexed as qvel and tau_ff (a ball joint may have a gain
  // per body-frame axis; root entries unused), N*m/rad and N*m*s/rad.
  std::array<double, kMaxDofs> kp{};
  std::array<double, kMaxDofs> kd{};
  // Torque limit per body (joint), on the norm of the joint's PD + feedforward
  // torque (0 = unlimited).
  std::array<double, kMaxBodies> torque_limit_nm{};

  // Root reference at the end of the step: imposed in kinematic mode, the
  // servo's target in free mode. Linear velocity in the world frame, angular
  // velocity in the root's body frame (the qvel layout of a free joint).
  Vec3 root_pos = Vec3::Zero();
  Quat root_quat = Quat::Identity();
  Vec3 root_lin_vel = Vec3::Zero();
  Vec3 root_ang_vel = Vec3::Zero();
  RootServo root_servo;
};

// Inputs that hold the model's rest pose with its default gains, the root
// reference at the model's rest root pose.
StepInputs make_inputs(const Model& model);

// The same gains on every dof of a body's joint (a per-joint shorthand).
void set_joint_gains(const Model& model, StepInputs& in, int body, double kp, double kd);
// Every dof of a body's joint scaled by these factors.
void scale_joint_gains(const Model& model, StepInputs& in, int body, double kp_factor, double kd_factor);

}  // namespace tonus::sim
