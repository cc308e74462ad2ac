// The physics step and the algorithms it is made of, as free functions over
// (Model, Data), named after what they compute (Pinocchio's style).
//
// One step (semi-implicit Euler, as MuJoCo's Euler integrator):
//   1. kinematics at (q, v);  2. bias forces (RNEA) and joint-space inertia (CRBA);
//   3. the drives' PD laws folded into the inertia (implicit) and factored (LTDL);
//   4. contacts and joint limits as velocity-level constraints (projected Gauss-Seidel,
//      Coulomb friction, restitution, speculative contacts);
//   5. v+ from the solve, q+ = q (+) dt v+; drive torques reported at v+.
// Deterministic: no clock, no threads, no allocation, no exceptions.
#pragma once

#include <span>

#include "tonus/sim/data.hpp"
#include "tonus/sim/inputs.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::sim {

// Advances `data` by model.timestep_s.
StepStatus step(const Model& model, Data& data, const StepInputs& inputs);

// Body and geom poses, centres of mass, dof axes and body velocities at the
// current (qpos, qvel).
void forward_kinematics(const Model& model, Data& data);

// Recursive Newton-Euler: the generalized forces that give the accelerations
// `qacc` at the current state, gravity included, contacts excluded.
// Needs forward_kinematics. Writes nv values to `tau`.
void inverse_dynamics(const Model& model, Data& data, std::span<const double> qacc, std::span<double> tau);

// Composite rigid body algorithm: data.mass (lower triangle, stride nv).
void mass_matrix(const Model& model, Data& data);

// Forward dynamics without contacts, limits or drives: qacc = M^-1 (tau - bias).
// Needs forward_kinematics. Uses data.factor as scratch.
void forward_dynamics(const Model& model, Data& data, std::span<const double> tau, std::span<double> qacc);

// q (+) dt v on the articulation's positions (quaternions renormalised).
void integrate_positions(const Model& model, std::span<double> qpos, std::span<const double> qvel, double dt_s);

// Energy and momentum of the articulation and the objects (needs forward_kinematics).
struct Energy {
  double kinetic_j = 0.0;
  double potential_j = 0.0;        // m g h relative to the world origin, with the model's gravity
  double objects_kinetic_j = 0.0;  // the objects' share of kinetic_j
  [[nodiscard]] double total_j() const { return kinetic_j + potential_j; }
};
Energy energy(const Model& model, const Data& data);

struct Momentum {
  Vec3 linear = Vec3::Zero();   // kg*m/s
  Vec3 angular = Vec3::Zero();  // about the world origin, kg*m^2/s
};
Momentum momentum(const Model& model, const Data& data);

// Sets the root mode; fixed and kinematic roots keep their current pose.
void set_root_mode(Data& data, RootMode mode);

}  // namespace tonus::sim
