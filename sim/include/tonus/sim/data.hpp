// The mutable half of the Model/Data split: the state of one simulation and
// every scratch array the step needs, sized at compile time. make_data()
// allocates it once; step() then never allocates.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/collision.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::sim {

// How the articulation's root moves (per Data, so simulation A and B of the
// dual scheme can differ):
//  fixed      the root stays where it is;
//  kinematic  the root follows StepInputs' root reference exactly, the rest is simulated;
//  free       the root is simulated (optionally helped by the root servo).
enum class RootMode : std::uint8_t { fixed, kinematic, free };

// A free rigid sphere or box, not part of the articulation.
struct ObjectSpec {
  Shape shape = Shape::sphere(0.05);
  double mass_kg = 1.0;
  Material material;
  Vec3 pos = Vec3::Zero();
  Quat quat = Quat::Identity();
  Vec3 lin_vel = Vec3::Zero();  // world
  Vec3 ang_vel = Vec3::Zero();  // world
};

struct Object {
  bool active = false;
  std::uint32_t generation = 0;  // bumped on every add, so stale handles are caught
  Shape shape;
  double mass_kg = 0.0;
  Vec3 inertia_diag = Vec3::Zero();  // principal moments, body frame (boxes and spheres are symmetric)
  Material material;
  Vec3 pos = Vec3::Zero();
  Quat quat = Quat::Identity();
  Vec3 lin_vel = Vec3::Zero();
  Vec3 ang_vel = Vec3::Zero();  // world
  Vec3 force = Vec3::Zero();    // external, world, applied during the next step only
};

// One side of a contact: an articulated body, an object, or the static ground.
struct ContactSide {
  enum class Kind : std::uint8_t { ground, body, object } kind = Kind::ground;
  int index = -1;  // body or object slot
  int geom = -1;   // geom of the body (articulation only)
};

struct Contact {
  ContactSide a;  // the normal points towards a
  ContactSide b;
  Vec3 pos = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  Vec3 tangent1 = Vec3::UnitX();
  Vec3 tangent2 = Vec3::UnitY();
  double dist_m = 0.0;
  double friction = 0.0;
  double restitution = 0.0;
  Vec3 impulse = Vec3::Zero();      // N*s on side a along (normal, tangent1, tangent2)
  Vec3 force_world = Vec3::Zero();  // N on side a, averaged over the step

  [[nodiscard]] double normal_force_n() const;
};

// Counters, as MuJoCo's warning statistics: the step never throws; what went
// wrong is counted here, and `last` tells the caller about the latest step.
struct Diagnostics {
  std::uint32_t bad_inputs = 0;          // non-finite or absurd inputs replaced by safe values
  std::uint32_t contact_overflow = 0;    // contact points dropped for want of room (the least important go first)
  std::uint32_t limit_overflow = 0;      // joint-limit rows dropped
  std::uint32_t torque_saturations = 0;  // drive torques clamped at their limit
  std::uint32_t solver_unconverged = 0;  // steps whose constraint solve ended above the tolerance (sweep cap)
  std::uint32_t divergences = 0;         // steps rejected as diverging (state restored)
  int solver_iterations = 0;             // last step: the most sweeps any island of contacts took
  int solver_islands = 0;                // last step: independent groups solved
  std::uint64_t solver_row_updates = 0;  // last step: row updates made (the solve's work)
  // Last step: the velocity-level complementarity error at the impulses found,
  // the largest over rows (m/s, rad/s): how far a row's velocity is from its
  // target while it pushes, how fast it still closes while it does not, how
  // far friction is from sticking or sliding at the cone. 0 without rows.
  double solver_residual = 0.0;
};

enum class StepStatus : std::uint8_t {
  ok,
  sanitized,  // some inputs were replaced (counted in bad_inputs); the step ran
  diverged,   // the state was about to become non-finite or explode: restored, caller should reset
};

// What this instance collides with, on top of the Model's features and
// ground: simulation A of the dual scheme runs without contacts (or with the
// ground only) from the same Model as simulation B.
struct CollisionSwitches {
  bool contacts = true;     // false: no contacts at all for this Data
  bool ground = true;       // false: nothing touches the ground plane
  bool objects = true;      // false: objects do not touch the articulation (they still meet the ground and each other)
  bool body_ground = true;  // false: the articulation does not touch the ground (objects still do)
};

struct Data {
  // ---- state -------------------------------------------------------------
  double time_s = 0.0;
  RootMode root_mode = RootMode::free;
  CollisionSwitches collisions;
  std::array<double, kMaxQpos> qpos{};
  std::array<double, kMaxDofs> qvel{};
  std::array<Object, kMaxObjects> objects{};

  // ---- outputs of the last step ------------------------------------------
  std::array<double, kMaxDofs> qacc{};             // (v+ - v) / dt
  std::array<double, kMaxDofs> tau_pd{};           // drive torque, PD part, as applied (generalized)
  std::array<double, kMaxDofs> tau_ff{};           // drive torque, feedforward part, as applied
  std::array<bool, kMaxBodies> drive_saturated{};  // the drive's torque sat on its limit
  Vec3 root_servo_force = Vec3::Zero();            // world, N
  Vec3 root_servo_torque = Vec3::Zero();           // world, N*m
  // The wrench the world applies to the root to move it as it moved: a
  // kinematic root's absorbed wrench (what holds the hips on the reference),
  // a free root's servo wrench, zero for a free root without servo. Force in
  // the world frame (N), torque in world axes about the root's origin (N*m),
  // averaged over the step.
  Vec3 root_wrench_force = Vec3::Zero();
  Vec3 root_wrench_torque = Vec3::Zero();
  std::array<Contact, kMaxContacts> contacts{};
  int ncon = 0;
  Diagnostics diag;
  StepStatus status = StepStatus::ok;

  // ---- kinematics at qpos (refreshed by forward_kinematics) --------------
  std::array<Pose, kMaxBodies> xbody{};  // body frames in the world
  std::array<Quat, kMaxBodies> xquat{};  // the same rotations as quaternions
  std::array<Vec3, kMaxBodies> xcom{};   // centres of mass in the world
  std::array<Pose, kMaxGeoms> xgeom{};
  Vec3 origin = Vec3::Zero();         // where spatial vectors are taken this step (the root)
  std::array<Vec6, kMaxDofs> cdof{};  // motion axis of each dof (angular; linear at origin), world
  std::array<Vec6, kMaxDofs> cdof_dot{};
  std::array<Vec6, kMaxBodies> cvel{};      // body spatial velocities (angular; linear at origin)
  std::array<Vec3, kMaxBodies> cinert_h{};  // spatial inertia about origin: first moment m * (com - origin)
  std::array<Mat3, kMaxBodies> cinert_i{};  // and rotational inertia about origin, world axes
  // The state the kinematics above were computed at: a step whose state is
  // bit for bit the one the previous step ended on skips recomputing them.
  std::array<double, kMaxQpos> kinematics_qpos{};
  std::array<double, kMaxDofs> kinematics_qvel{};

  // ---- dynamics scratch ----------------------------------------------------
  std::array<double, kMaxDofs * kMaxDofs> mass{};    // joint-space inertia, lower triangle, row stride nv
  std::array<double, kMaxDofs * kMaxDofs> factor{};  // M + dt*Kd + dt^2*Kp, factored in place (LTDL)
  std::array<double, kMaxDofs> bias{};               // C(q, v) + gravity
  std::array<double, kMaxDofs> drive_kp{};           // the inputs, checked (bad values replaced)
  std::array<double, kMaxDofs> drive_kd{};
  std::array<double, kMaxBodies> drive_limit{};
  std::array<double, kMaxDofs> drive_ff{};
  // Drives that reached their torque limit are solved as bounded rows (see
  // drives.cpp); they stay there while they press against the limit.
  std::array<bool, kMaxBodies> drive_in_rows{};
  std::array<double, kMaxDofs> drive_impulse{};  // their last impulse (warm start), N*m*s
  std::array<double, kMaxDofs> law_kp{};         // each drive's law per dof this step
  std::array<double, kMaxDofs> law_kd{};
  std::array<double, kMaxDofs> kp_dof{};  // the part folded into the inertia this pass
  std::array<double, kMaxDofs> kd_dof{};
  std::array<double, kMaxDofs> err_dof{};  // drive position error per dof (rad, m)
  std::array<double, kMaxDofs> vref_dof{};
  std::array<double, kMaxDofs> tau_fixed{};  // explicit torques: feedforward, explicit PD, saturated drives
  std::array<double, kMaxDofs> qvel_free{};  // after forces and drives, before constraints
  std::array<double, kMaxDofs> qvel_next{};  // after constraints: the end-of-step velocity
  std::array<double, kMaxDofs> work{};
  int first_active_dof = 0;         // dofs below are prescribed (fixed or kinematic root)
  std::array<double, 6> root_dv{};  // prescribed root velocity change this step
  std::array<double, kMaxQpos> qpos_saved{};
  std::array<double, kMaxDofs> qvel_saved{};
  std::array<Object, kMaxObjects> objects_saved{};

  // ---- objects scratch ---------------------------------------------------
  std::array<Vec3, kMaxObjects> obj_lin_free{};
  std::array<Vec3, kMaxObjects> obj_ang_free{};
  std::array<Vec3, kMaxObjects> obj_lin_next{};
  std::array<Vec3, kMaxObjects> obj_ang_next{};
  std::array<Mat3, kMaxObjects> obj_inv_inertia{};  // world

  // ---- constraint rows (contacts and limits) ------------------------------
  // One scalar constraint. A contact row measures the relative velocity of
  // its two sides along a direction: row velocity = ua . V_a + ub . V_b, with
  // V = (angular; linear at data.origin) for bodies and (angular; linear at
  // the centre) for objects. Limit and drive rows act on their joint's own dofs.
  struct Row {
    enum class Kind : std::uint8_t { normal, friction1, friction2, limit, drive } kind = Kind::normal;
    ContactSide a, b;
    Vec6 ua = Vec6::Zero();
    Vec6 ub = Vec6::Zero();
    Vec3 ia = Vec3::Zero();  // an object side's world inverse inertia times ua's (ub's) angular part
    Vec3 ib = Vec3::Zero();
    double inv_mass_a = 0.0;  // an object side's inverse mass (0 for others)
    double inv_mass_b = 0.0;
    int limit_body = -1;
    Vec3 limit_coef = Vec3::Zero();  // on the joint's dofs (the first dof_num entries)
    double target = 0.0;             // desired row velocity (gap closing, restitution, Baumgarte)
    double lambda = 0.0;             // impulse, N*s or N*m*s
    double cfm = 0.0;                // compliance of a drive row: 1 / (dt (Kd + dt Kp))
    double bound = 0.0;              // impulse cap (a drive group: on its norm; see row_ops.hpp)
    double diag = 0.0;               // effective inverse mass along the row: (J M~^-1 J^T)_rr
    double v0 = 0.0;                 // row velocity at the unconstrained end-of-step velocities
    double pre = 0.0;                // row velocity at the start of the step
    int group = -1;                  // a drive row's first row (a ball joint's three rows are projected together)
    int contact = -1;
    int island = -1;      // the independent group the row is solved in
    int jac_offset = -1;  // its packed whitened Jacobian in jac_values (rows on the articulation)
    int jac_size = 0;
    std::uint64_t support = 0;  // dofs the row touches (bit k: dof k)
  };
  std::array<Row, kMaxRows> rows{};
  int nrows = 0;
  int njoint_rows = 0;
  int nbase_rows = 0;  // contact and limit rows; drive rows follow
  // y = D^-1/2 L^-T J^T of each row on the articulation (with M~ = L^T D L),
  // packed over the row's support: (J M~^-1 J^T)_rs = y_r . y_s.
  std::array<double, kRowJacobianPool> jac_values{};
  std::array<std::uint8_t, kRowJacobianPool> jac_dofs{};
  int jac_used = 0;
  int jac_base_used = 0;  // taken by contact and limit rows; drive rows follow
  // Solver state: the whitened impulse sum on the articulation (sum of y_r lambda_r)
  // and each object's velocity change, so a row's velocity costs its own size only.
  std::array<double, kMaxDofs> solve_w{};
  std::array<Vec3, kMaxObjects> obj_dlin{};
  std::array<Vec3, kMaxObjects> obj_dang{};
  std::array<double, kMaxRows> solve_before{};      // impulses before the sweep
  std::array<double, kMaxRows> solve_dir{};         // the conjugate direction (see solver.cpp)
  std::array<double, kMaxRows> solve_checkpoint{};  // impulses before a subspace step on trial (solver.cpp)
  std::array<double, kSubspaceRows * kSubspaceRows> subspace_matrix{};  // the subspace step (solver.cpp)
  std::array<double, kSubspaceRows> subspace_rhs{};
  std::array<int, kSubspaceRows> subspace_rows{};
  // Islands: the articulation is node 0, object i node i + 1; rows joining
  // nodes join their islands (the ground joins nothing).
  std::array<int, kMaxObjects + 1> island_parent{};
  std::array<int, kMaxObjects + 2> island_start{};  // rows of island s: island_rows[island_start[s] ..]
  std::array<int, kMaxRows> island_rows{};
  int nislands = 0;
  std::array<Contact, kMaxContacts> prev_contacts{};    // last step's, for warm starting
  std::array<std::uint64_t, kMaxContacts> prev_keys{};  // their side pairs, sorted with prev_order
  std::array<std::uint16_t, kMaxContacts> prev_order{};
  int prev_ncon = 0;
  // Contact selection past kMaxContacts: each contact's importance, and a min-heap over them.
  std::array<double, kMaxContacts> contact_priority{};
  std::array<std::uint16_t, kMaxContacts> contact_heap{};
};

// Allocates and initialises a Data for `model` at its rest configuration
// (the only allocation; everything after is in place).
std::unique_ptr<Data> make_data(const Model& model);

// Back to the rest configuration: zero velocities, no objects, counters cleared.
void reset_data(const Model& model, Data& data);

}  // namespace tonus::sim
