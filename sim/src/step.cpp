// step(): the stages in order, the torque-limit passes, integration, and the
// guards that keep a bad input or a diverging state from propagating.
#include "tonus/sim/step.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "row_ops.hpp"
#include "stages.hpp"

namespace tonus::sim {
namespace {

using std::size_t;

// Debug builds (EIGEN_RUNTIME_NO_MALLOC) abort on any Eigen heap allocation inside the step.
struct NoEigenMalloc {
#ifdef EIGEN_RUNTIME_NO_MALLOC
  NoEigenMalloc() { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoEigenMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
#else
  NoEigenMalloc() = default;
#endif
  NoEigenMalloc(const NoEigenMalloc&) = delete;
  NoEigenMalloc& operator=(const NoEigenMalloc&) = delete;
};

bool state_ok(const Model& model, const Data& data) {
  const double vmax = model.solver.max_speed;
  for (size_t k = 0; k < static_cast<size_t>(model.nq); ++k) {
    if (!std::isfinite(data.qpos[k])) return false;
  }
  for (size_t k = 0; k < static_cast<size_t>(model.nv); ++k) {
    if (!(std::abs(data.qvel[k]) <= vmax)) return false;  // false for NaN too
  }
  for (const Object& o : data.objects) {
    if (!o.active) continue;
    if (!all_finite(o.pos) || !(o.lin_vel.norm() <= vmax) || !(o.ang_vel.norm() <= vmax)) return false;
  }
  return true;
}

void save_state(const Model& model, Data& data) {
  std::copy_n(data.qpos.begin(), model.nq, data.qpos_saved.begin());
  std::copy_n(data.qvel.begin(), model.nv, data.qvel_saved.begin());
  data.objects_saved = data.objects;
}

}  // namespace

namespace detail {

void integrate_objects(Data& data, const std::array<Vec3, kMaxObjects>& lin, const std::array<Vec3, kMaxObjects>& ang,
                       double dt_s) {
  for (size_t i = 0; i < kMaxObjects; ++i) {
    Object& o = data.objects[i];
    if (!o.active) continue;
    o.lin_vel = lin[i];
    o.ang_vel = ang[i];
    o.pos += dt_s * o.lin_vel;
    o.quat = (quat_exp(o.ang_vel * dt_s) * o.quat).normalized();  // world-frame angular velocity: left multiply
    o.force.setZero();
  }
}

void snap_kinematic_root(const Model& model, Data& data, const StepInputs& in) {
  if (model.bodies[0].joint != JointType::free || data.root_mode != RootMode::kinematic) return;
  const double n = in.root_quat.norm();
  if (!all_finite(in.root_pos) || !std::isfinite(n) || n < 0.5) return;  // counted in read_inputs
  // A kinematic root sits exactly on its reference (no integration drift).
  const Quat q = in.root_quat.normalized();
  data.qpos[0] = in.root_pos.x();
  data.qpos[1] = in.root_pos.y();
  data.qpos[2] = in.root_pos.z();
  data.qpos[3] = q.w();
  data.qpos[4] = q.x();
  data.qpos[5] = q.y();
  data.qpos[6] = q.z();
}

void integrate(const Model& model, Data& data, const StepInputs& in) {
  const double dt = model.timestep_s;
  const auto nv = static_cast<size_t>(model.nv);
  for (size_t k = 0; k < nv; ++k) data.qacc[k] = (data.qvel_next[k] - data.qvel[k]) / dt;
  std::copy_n(data.qvel_next.begin(), nv, data.qvel.begin());
  integrate_positions(model, data.qpos, data.qvel, dt);
  snap_kinematic_root(model, data, in);
  integrate_objects(data, data.obj_lin_next, data.obj_ang_next, dt);
}

}  // namespace detail

void integrate_positions(const Model& model, std::span<double> qpos, std::span<const double> qvel, double dt_s) {
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    const auto q = static_cast<size_t>(b.qpos_adr);
    const auto d = static_cast<size_t>(b.dof_adr);
    switch (b.joint) {
      case JointType::free: {
        for (size_t k = 0; k < 3; ++k) qpos[q + k] += dt_s * qvel[d + k];
        const Quat r = quat_integrate(Quat(qpos[q + 3], qpos[q + 4], qpos[q + 5], qpos[q + 6]).normalized(),
                                      Vec3(qvel[d + 3], qvel[d + 4], qvel[d + 5]), dt_s);
        qpos[q + 3] = r.w();
        qpos[q + 4] = r.x();
        qpos[q + 5] = r.y();
        qpos[q + 6] = r.z();
        break;
      }
      case JointType::ball: {
        const Quat r = quat_integrate(Quat(qpos[q], qpos[q + 1], qpos[q + 2], qpos[q + 3]).normalized(),
                                      Vec3(qvel[d], qvel[d + 1], qvel[d + 2]), dt_s);
        qpos[q] = r.w();
        qpos[q + 1] = r.x();
        qpos[q + 2] = r.y();
        qpos[q + 3] = r.z();
        break;
      }
      case JointType::hinge: qpos[q] += dt_s * qvel[d]; break;
      case JointType::fixed: break;
    }
  }
}

void set_root_mode(Data& data, RootMode mode) {
  data.root_mode = mode;
  if (mode == RootMode::fixed) std::fill_n(data.qvel.begin(), 6, 0.0);
}

namespace {

void report_root_servo(const Model& model, Data& data) {
  if (model.bodies[0].joint != JointType::free) return;
  const Mat3& r = data.xbody[0].rot;
  data.root_servo_force = Vec3(data.tau_pd[0], data.tau_pd[1], data.tau_pd[2]);
  data.root_servo_torque = r * Vec3(data.tau_pd[3], data.tau_pd[4], data.tau_pd[5]);
}

// The wrench the world applies to a prescribed (kinematic or fixed) root over the step: the root
// rows of M a + c + g minus the contacts' generalized impulse on them (joint
// drives and limits act on their own joint's dofs only). Evaluated at the
// start-of-step kinematics the step used.
void report_kinematic_root_wrench(const Model& model, Data& data) {
  const double dt = model.timestep_s;
  const auto nv = static_cast<size_t>(model.nv);
  std::array<double, 6> f{};
  for (size_t p = 0; p < 6; ++p) {
    double s = data.bias[p];
    for (size_t j = 0; j <= p; ++j) s += data.mass[p * nv + j] * (data.qvel_next[j] - data.qvel[j]) / dt;
    for (size_t k = p + 1; k < nv; ++k) s += data.mass[k * nv + p] * (data.qvel_next[k] - data.qvel[k]) / dt;
    f[p] = s;
  }
  for (int r = 0; r < data.nrows; ++r) {
    const Data::Row& row = data.rows[static_cast<size_t>(r)];
    if (detail::is_joint_row(row) || row.lambda == 0.0) continue;
    for (const auto* side : {&row.a, &row.b}) {
      if (side->kind != ContactSide::Kind::body) continue;
      const Vec6& u = side == &row.a ? row.ua : row.ub;
      for (size_t p = 0; p < 6; ++p) f[p] -= u.dot(data.cdof[p]) * row.lambda / dt;
    }
  }
  data.root_wrench_force = Vec3(f[0], f[1], f[2]);
  data.root_wrench_torque = data.xbody[0].rot * Vec3(f[3], f[4], f[5]);
}

void report_root_wrench(const Model& model, Data& data) {
  data.root_wrench_force.setZero();
  data.root_wrench_torque.setZero();
  if (model.bodies[0].joint != JointType::free) return;
  if (data.root_mode != RootMode::free) {  // kinematic or fixed: prescribed
    report_kinematic_root_wrench(model, data);
  } else if (data.root_mode == RootMode::free) {
    data.root_wrench_force = data.root_servo_force;
    data.root_wrench_torque = data.root_servo_torque;
  }
}

// The kinematics are a function of (qpos, qvel) alone: when the state is bit
// for bit the one they were last computed at (the end of the previous step,
// unless the caller changed it), they are still right.
void refresh_kinematics(const Model& model, Data& data) {
  const auto q_bytes = static_cast<size_t>(model.nq) * sizeof(double);
  const auto v_bytes = static_cast<size_t>(model.nv) * sizeof(double);
  if (std::memcmp(data.qpos.data(), data.kinematics_qpos.data(), q_bytes) == 0 &&
      std::memcmp(data.qvel.data(), data.kinematics_qvel.data(), v_bytes) == 0)
    return;
  forward_kinematics(model, data);
}

// The real-time step: semi-implicit Euler with implicit drives and constraints.
bool step_euler(const Model& model, Data& data, const StepInputs& inputs) {
  refresh_kinematics(model, data);
  mass_matrix(model, data);
  const std::array<double, kMaxDofs> zero{};
  inverse_dynamics(model, data, zero, data.bias);
  detail::objects_free_velocity(model, data);
  detail::detect_contacts(model, data);
  detail::build_rows(model, data);
  detail::drive_errors(model, data, inputs);
  if (inputs.scheme != DriveScheme::implicit) data.drive_in_rows.fill(false);

  // Usually one pass; another when a drive crosses its torque limit and moves
  // from the factorisation into the rows.
  bool ok = true;
  for (int pass = 0;; ++pass) {
    detail::drive_terms(model, data, inputs.scheme);
    detail::add_drive_rows(model, data);
    if (!detail::free_velocity(model, data)) {
      ok = false;
      break;
    }
    detail::assemble_rows(model, data);
    detail::solve_rows(model, data);
    detail::apply_impulses(model, data);
    const bool moved = detail::drive_torques(model, data, inputs.scheme);
    if (!moved || pass >= model.solver.torque_limit_passes) break;
  }

  if (!ok) return false;
  detail::release_drive_rows(model, data);
  report_root_servo(model, data);
  report_root_wrench(model, data);
  detail::integrate(model, data, inputs);
  detail::report_contacts(model, data);
  return true;
}

// Classic RK4 over (q, v), MuJoCo's tableau and position update: stage
// positions are q0 (+) h * (combined stage velocities). Drives are explicit
// at each stage; the model has no contacts or limits (the builder checks).
bool step_rk4(const Model& model, Data& data, const StepInputs& inputs) {
  constexpr double kA[3] = {0.5, 0.5, 1.0};  // the tableau is diagonal: stage i uses stage i-1 only
  constexpr double kB[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
  const double h = model.timestep_s;
  const auto nv = static_cast<size_t>(model.nv);
  std::array<std::array<double, kMaxDofs>, 4> vel{};
  std::array<std::array<double, kMaxDofs>, 4> acc{};
  std::array<double, kMaxDofs> dx{};
  const auto stage = [&](size_t i) {
    forward_kinematics(model, data);
    mass_matrix(model, data);
    const std::array<double, kMaxDofs> zero{};
    inverse_dynamics(model, data, zero, data.bias);
    detail::drive_errors(model, data, inputs);
    detail::drive_terms(model, data, DriveScheme::explicit_baseline);
    if (!detail::free_velocity(model, data)) return false;
    for (size_t k = 0; k < nv; ++k) {
      vel[i][k] = data.qvel[k];
      acc[i][k] = (data.qvel_free[k] - data.qvel[k]) / h;
    }
    return true;
  };
  if (!stage(0)) return false;
  detail::drive_torques(model, data, DriveScheme::explicit_baseline);  // report the start-of-step torques
  report_root_servo(model, data);
  for (size_t i = 1; i < 4; ++i) {
    for (size_t k = 0; k < nv; ++k) dx[k] = kA[i - 1] * vel[i - 1][k];
    std::copy_n(data.qpos_saved.begin(), model.nq, data.qpos.begin());
    integrate_positions(model, data.qpos, dx, h);
    for (size_t k = 0; k < nv; ++k) data.qvel[k] = data.qvel_saved[k] + h * kA[i - 1] * acc[i - 1][k];
    if (!stage(i)) return false;
  }
  std::copy_n(data.qpos_saved.begin(), model.nq, data.qpos.begin());
  for (size_t k = 0; k < nv; ++k) {
    dx[k] = 0.0;
    double a = 0.0;
    for (size_t i = 0; i < 4; ++i) {
      dx[k] += kB[i] * vel[i][k];
      a += kB[i] * acc[i][k];
    }
    data.qacc[k] = a;
    data.qvel[k] = data.qvel_saved[k] + h * a;
  }
  integrate_positions(model, data.qpos, dx, h);
  detail::snap_kinematic_root(model, data, inputs);
  // Objects: free flight (an rk4 model has no contacts).
  detail::objects_free_velocity(model, data);
  detail::integrate_objects(data, data.obj_lin_free, data.obj_ang_free, h);
  data.ncon = 0;
  return true;
}

}  // namespace

StepStatus step(const Model& model, Data& data, const StepInputs& inputs) {
  [[maybe_unused]] const NoEigenMalloc guard;
  if (!state_ok(model, data)) {  // a state broken before the step (e.g. written by the caller): refuse
    ++data.diag.divergences;
    data.status = StepStatus::diverged;
    return data.status;
  }
  save_state(model, data);
  const int bad = detail::read_inputs(model, data, inputs);
  data.diag.bad_inputs += static_cast<std::uint32_t>(bad);
  bool ok = model.integrator == Integrator::rk4 ? step_rk4(model, data, inputs) : step_euler(model, data, inputs);
  ok = ok && state_ok(model, data);
  if (!ok) {
    std::copy_n(data.qpos_saved.begin(), model.nq, data.qpos.begin());
    std::copy_n(data.qvel_saved.begin(), model.nv, data.qvel.begin());
    data.objects = data.objects_saved;
    ++data.diag.divergences;
    data.status = StepStatus::diverged;
    forward_kinematics(model, data);
    return data.status;
  }
  for (int i = 0; i < model.nbody; ++i)
    data.diag.torque_saturations += data.drive_saturated[static_cast<size_t>(i)] ? 1U : 0U;
  data.time_s += model.timestep_s;
  forward_kinematics(model, data);
  data.status = bad > 0 ? StepStatus::sanitized : StepStatus::ok;
  return data.status;
}

}  // namespace tonus::sim
