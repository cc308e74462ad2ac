// The stages of one step, each a plain function of (Model, Data), in the
// order step() calls them. Private to sim/.
#pragma once

#include "tonus/sim/data.hpp"
#include "tonus/sim/inputs.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::sim::detail {

// Copies the inputs into data.drive_* and the root's prescribed velocity
// change, replacing non-finite or absurd values by safe ones. Returns how
// many values were replaced.
int read_inputs(const Model& model, Data& data, const StepInputs& inputs);

// Each drive's law per dof: gains, position error, reference velocity (once per step).
void drive_errors(const Model& model, Data& data, const StepInputs& inputs);

// This pass's split of the laws: into the inertia (kp_dof, kd_dof), into
// explicit torques (tau_fixed: feedforward, explicit scheme), or into rows.
void drive_terms(const Model& model, Data& data, DriveScheme scheme);

// Bounded compliant rows for the drives that reached their torque limit
// (after the contact and limit rows).
void add_drive_rows(const Model& model, Data& data);

// M + dt*Kd + dt^2*Kp on the simulated dofs, factored; then the velocity
// the articulation would reach without constraints (data.qvel_free).
// False when the matrix is not positive definite.
bool free_velocity(const Model& model, Data& data);

// Drive torques as applied; moves drives over their limit into rows.
// Returns true when one moved (the pass must be redone).
bool drive_torques(const Model& model, Data& data, DriveScheme scheme);

// After the step: drives well inside their limit leave the rows.
void release_drive_rows(const Model& model, Data& data);

// Objects: gravity, external force, gyroscopic term; world inverse inertia.
void objects_free_velocity(const Model& model, Data& data);

// Collision detection into data.contacts (warm-started from last step's).
void detect_contacts(const Model& model, Data& data);

// Contact rows (normal and two friction rows each) and joint-limit rows.
void build_rows(const Model& model, Data& data);

// Effective masses (J M~^-1 J^T), row velocities at v_free, targets.
void assemble_rows(const Model& model, Data& data);

// Projected Gauss-Seidel on the rows, island by island, to a residual
// (solver.cpp); then qvel and object velocities.
void solve_rows(const Model& model, Data& data);
void apply_impulses(const Model& model, Data& data);

// q (+) dt v for the articulation and the objects; kinematic roots snap to their reference.
void integrate(const Model& model, Data& data, const StepInputs& inputs);
void snap_kinematic_root(const Model& model, Data& data, const StepInputs& inputs);
void integrate_objects(Data& data, const std::array<Vec3, kMaxObjects>& lin, const std::array<Vec3, kMaxObjects>& ang,
                       double dt_s);

// Contact forces for the caller (impulse / dt) and warm-start memory.
void report_contacts(const Model& model, Data& data);
void remember_contacts(Data& data);  // this step's contacts, indexed by their sides, for the next warm start

}  // namespace tonus::sim::detail
