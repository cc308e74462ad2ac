// Checks and differences of reference poses (private to host/avatar).
#pragma once

#include <span>

#include "tonus/host/avatar/reference.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::avatar::detail {

// Every position finite, every quaternion of a usable norm (0.5..2), and the
// velocities finite and below 1e3 (m/s, rad/s) when given.
bool reference_usable(const sim::Model& model, const ReferencePose& ref);

// Quaternions scaled to unit norm.
void normalize(const sim::Model& model, ReferencePose& ref);

struct StepSize {
  double joint_rad = 0.0;  // the largest joint rotation between the two
  double root_m = 0.0;     // the root's displacement
};
StepSize step_size(const sim::Model& model, std::span<const double> q0, std::span<const double> q1);

// Velocities taking q0 to q1 in dt (the qvel layout: root linear world, angular root frame).
void difference(const sim::Model& model, std::span<const double> q0, std::span<const double> q1, double dt_s,
                std::span<double> qvel);

// Per body: the angle between the two configurations' joint rotations (hinge: |difference|; root: 0).
void joint_angles_between(const sim::Model& model, std::span<const double> q0, std::span<const double> q1,
                          std::span<double> out);

}  // namespace tonus::avatar::detail
