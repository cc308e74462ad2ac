// The immutable model: an articulated tree of rigid bodies (reduced
// coordinates), its collision shapes, the ground and the solver options.
// Built once by ModelBuilder (which checks every field), then shared by any
// number of Data instances (simulation A and B of the dual PD scheme).
//
// State layout (MuJoCo's, so the MJCF export and the validation compare like
// with like):
//   free joint  qpos = position (3, world) + quaternion (4, w x y z)
//               qvel = linear velocity of the body origin (3, world) + angular velocity (3, body frame)
//   ball joint  qpos = quaternion (4) relative to the rest orientation, qvel = angular velocity (3, body frame)
//   hinge       qpos = angle (1), qvel = angular rate (1) about the body-frame axis
//   fixed       nothing
// A body's frame sits at its joint; at rest it is offset from the parent's
// frame by pos_in_parent and rotated by quat_in_parent.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/geometry.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::sim {

static_assert(kMaxDofs <= 64 && kMaxBodies <= 32, "dof and body sets are kept as bit masks");

enum class JointType : std::uint8_t { free, ball, hinge, fixed };

constexpr int joint_dofs(JointType t) {
  switch (t) {
    case JointType::free: return 6;
    case JointType::ball: return 3;
    case JointType::hinge: return 1;
    case JointType::fixed: return 0;
  }
  return 0;
}
constexpr int joint_qpos(JointType t) {
  switch (t) {
    case JointType::free: return 7;
    case JointType::ball: return 4;
    case JointType::hinge: return 1;
    case JointType::fixed: return 0;
  }
  return 0;
}

// Joint range. Hinge: [lower_rad, upper_rad]. Ball: a swing cone of half
// angle swing_max_rad around twist_axis (body frame) and a twist range
// [lower_rad, upper_rad] about it.
struct JointLimit {
  bool enabled = false;
  double lower_rad = 0.0;
  double upper_rad = 0.0;
  double swing_max_rad = 0.0;
  Vec3 twist_axis = Vec3::UnitZ();
};

// Default PD drive of a joint (the step's inputs start from these).
struct DriveDefaults {
  double kp = 0.0;               // N*m/rad
  double kd = 0.0;               // N*m*s/rad
  double torque_limit_nm = 0.0;  // 0 = unlimited
};

struct Body {
  std::array<char, kNameLength> name{};
  int parent = -1;  // -1: attached to the world (only the root)
  JointType joint = JointType::fixed;
  Vec3 pos_in_parent = Vec3::Zero();
  Quat quat_in_parent = Quat::Identity();
  Vec3 hinge_axis = Vec3::UnitX();  // body frame, unit
  double mass_kg = 0.0;
  Vec3 com = Vec3::Zero();      // body frame
  Mat3 inertia = Mat3::Zero();  // about the centre of mass, body-frame axes, kg*m^2
  JointLimit limit;
  DriveDefaults drive;
  // Added to the joint-space inertia of the joint's dofs (MuJoCo's armature,
  // kg*m^2): the reflected inertia of an actuator, and for light distal links
  // what keeps explicit velocity-product terms stable.
  double armature = 0.0;

  // Filled by the builder.
  int dof_adr = 0;  // first velocity index
  int dof_num = 0;
  int qpos_adr = 0;  // first position index
  int qpos_num = 0;
  int last_path_dof = -1;  // the deepest dof on the path root -> this body (-1: none)

  [[nodiscard]] std::string_view name_view() const { return {name.data()}; }
};

// Contact material.
struct Material {
  double friction = 0.8;     // Coulomb coefficient
  double restitution = 0.0;  // normal velocity ratio out/in (combined: the larger of a pair's two)
};

struct Geom {
  int body = 0;
  Shape shape;
  Pose local;  // in the body frame
  Material material;
  bool collides_with_ground = true;
  bool collides_with_objects = true;
};

struct Ground {
  bool enabled = true;
  Vec3 normal = Vec3::UnitZ();  // unit; tilt it for a slope
  double offset_m = 0.0;        // plane: normal . x = offset
  Material material;
};

// Which parts of the dynamics run (MuJoCo's disable flags, as positives).
struct Features {
  bool gravity = true;
  bool contacts = true;
  bool limits = true;
  bool self_collision = false;
};

struct SolverOptions {
  int iterations = 200;                    // projected Gauss-Seidel sweeps per island, at most
  double tolerance = 1e-6;                 // velocity-level residual to reach (m/s, rad/s); see solver.cpp
  double baumgarte = 0.2;                  // fraction of a penetration corrected per step
  double penetration_slop_m = 5e-4;        // penetration left alone (keeps resting contacts quiet)
  double contact_margin_m = 0.01;          // speculative distance, plus what the shapes sweep in one step
  double restitution_threshold_mps = 0.5;  // slower impacts do not bounce
  double limit_margin_rad = 0.05;          // speculative angle for joint limits
  int torque_limit_passes = 4;             // re-solves when a drive saturates
  double max_speed = 1e4;                  // any generalized velocity beyond this (m/s or rad/s) is divergence
  // Contact points kept per step, at most kMaxContacts: a lower cap bounds the
  // solve's cost; past it the least important points go (see contacts.cpp).
  int max_contacts = static_cast<int>(kMaxContacts);
};

// Semi-implicit Euler (MuJoCo's "Euler") is the real-time integrator: drives,
// contacts and limits are solved implicitly at the end-of-step velocity.
// Classic RK4 (MuJoCo's "RK4") integrates contact- and limit-free models to
// fourth order, for analysis and validation (energy conservation); there the
// drives act explicitly at each stage.
enum class Integrator : std::uint8_t { euler, rk4 };

struct Model {
  int nbody = 0;
  int nq = 0;
  int nv = 0;
  int ngeom = 0;
  std::array<Body, kMaxBodies> bodies{};
  std::array<Geom, kMaxGeoms> geoms{};
  std::array<int, kMaxDofs> dof_body{};
  std::array<int, kMaxDofs> dof_parent{};  // previous dof on the path to the root (-1: none)
  std::array<double, kMaxDofs> dof_kp{};   // defaults per dof, copied from the bodies' drives
  std::array<double, kMaxDofs> dof_kd{};
  std::array<double, kMaxQpos> qpos0{};                    // rest configuration (identity quaternions, zero angles)
  std::array<std::uint64_t, kMaxBodies> body_path_dofs{};  // bit k set: dof k lies on the path root -> body
  std::array<std::uint32_t, kMaxBodies> body_ancestors{};  // bit j set: body j is the body or an ancestor

  double timestep_s = 1e-3;
  Integrator integrator = Integrator::euler;
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
  Ground ground;
  Features features;
  SolverOptions solver;

  [[nodiscard]] double total_mass_kg() const;
  // Index of the body named `name`, or -1.
  [[nodiscard]] int body_index(std::string_view name) const;
  // Index of the first geom on `body`, or -1 (the humanoid has one per body).
  [[nodiscard]] int first_geom(int body) const;
};

}  // namespace tonus::sim
