// The PD drives and the root servo. Each drive's law is evaluated at the
// end-of-step state (implicit, "stable PD"):
//   tau = -Kp (e + dt v+) - Kd (v+ - vref) + tau_ff.
// Drives within their torque limit fold Kp and Kd into the joint-space
// inertia and are solved exactly by the factorisation:
//   (M + dt Kd + dt^2 Kp) dv = dt (tau_ff - c - Kp (e + dt v) - Kd (v - vref)).
// A drive whose law exceeds its limit leaves the inertia and becomes a
// compliant row of the constraint solve (ODE/Springhead's soft constraint:
// compliance 1 / (dt (Kd + dt Kp))) whose impulse is bounded by the limit, so
// it yields exactly as much as the limit makes it, coupled with the contacts.
// An explicit clamped torque would not do: on a light axis (an arm's twist)
// it overshoots within one step and chatters.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "ltdl.hpp"
#include "row_ops.hpp"
#include "stages.hpp"

namespace tonus::sim::detail {
namespace {

using std::size_t;

bool finite(double x) { return std::isfinite(x); }

Quat read_quat(const std::array<double, kMaxQpos>& q, int adr) {
  const auto a = static_cast<size_t>(adr);
  return {q[a], q[a + 1], q[a + 2], q[a + 3]};
}

// A finite, non-negative value, or 0 (counted) otherwise.
double gain_or_zero(double x, int& bad) {
  if (finite(x) && x >= 0.0) return x;
  ++bad;
  return 0.0;
}

bool root_is_free_joint(const Model& model) { return model.bodies[0].joint == JointType::free; }

}  // namespace

int read_inputs(const Model& model, Data& data, const StepInputs& in) {
  int bad = 0;
  const auto nbody = static_cast<size_t>(model.nbody);
  for (size_t i = 0; i < nbody; ++i) data.drive_limit[i] = gain_or_zero(in.torque_limit_nm[i], bad);
  // Root dofs carry no drive (the root servo has its own gains).
  const size_t first_joint_dof = root_is_free_joint(model) ? 6 : 0;
  for (size_t d = 0; d < static_cast<size_t>(model.nv); ++d) {
    data.drive_kp[d] = d < first_joint_dof ? 0.0 : gain_or_zero(in.kp[d], bad);
    data.drive_kd[d] = d < first_joint_dof ? 0.0 : gain_or_zero(in.kd[d], bad);
  }
  for (size_t d = 0; d < static_cast<size_t>(model.nv); ++d) {
    const double t = in.tau_ff[d];
    if (finite(t) && std::abs(t) < 1e9) {
      data.drive_ff[d] = t;
    } else {
      data.drive_ff[d] = 0.0;
      ++bad;
    }
  }

  // Which dofs are simulated, and how a prescribed root changes velocity.
  data.first_active_dof = 0;
  data.root_dv.fill(0.0);
  if (root_is_free_joint(model) && data.root_mode != RootMode::free) {
    data.first_active_dof = 6;
    if (data.root_mode == RootMode::kinematic) {
      const bool ok = all_finite(in.root_lin_vel) && all_finite(in.root_ang_vel) && all_finite(in.root_pos) &&
                      finite(in.root_quat.w()) && all_finite(in.root_quat.vec()) && in.root_quat.norm() > 0.5;
      if (ok) {
        for (size_t k = 0; k < 3; ++k) {
          data.root_dv[k] = in.root_lin_vel(static_cast<Eigen::Index>(k)) - data.qvel[k];
          data.root_dv[k + 3] = in.root_ang_vel(static_cast<Eigen::Index>(k)) - data.qvel[k + 3];
        }
      } else {
        ++bad;  // hold the root still rather than follow a broken reference
        for (size_t k = 0; k < 6; ++k) data.root_dv[k] = -data.qvel[k];
      }
    } else {
      for (size_t k = 0; k < 6; ++k) data.root_dv[k] = -data.qvel[k];
    }
  }
  data.drive_saturated.fill(false);
  return bad;
}

void drive_errors(const Model& model, Data& data, const StepInputs& in) {
  const auto nv = static_cast<size_t>(model.nv);
  std::fill_n(data.law_kp.begin(), nv, 0.0);
  std::fill_n(data.law_kd.begin(), nv, 0.0);
  std::fill_n(data.err_dof.begin(), nv, 0.0);
  std::fill_n(data.vref_dof.begin(), nv, 0.0);
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const auto q0 = static_cast<size_t>(b.qpos_adr);
    Vec3 err = Vec3::Zero();
    bool has_target = true;
    switch (b.joint) {
      case JointType::hinge: {
        const double target = in.target_qpos[q0];
        err.x() = finite(target) ? data.qpos[q0] - target : 0.0;
        break;
      }
      case JointType::ball: {
        Quat target = read_quat(in.target_qpos, b.qpos_adr);
        const double n = target.norm();
        if (finite(n) && n > 0.5 && n < 2.0) {
          target.coeffs() /= n;
          err = quat_log(target.conjugate() * read_quat(data.qpos, b.qpos_adr).normalized());
        } else {
          has_target = false;  // no usable target: the drive only damps
        }
        break;
      }
      case JointType::free: {
        // The root servo, in free mode only.
        const RootServo& s = in.root_servo;
        const bool usable = s.enabled && data.root_mode == RootMode::free && all_finite(in.root_pos) &&
                            all_finite(in.root_lin_vel) && all_finite(in.root_ang_vel) && finite(in.root_quat.norm()) &&
                            in.root_quat.norm() > 0.5;
        if (!usable) continue;
        const Vec3 pos(data.qpos[q0], data.qpos[q0 + 1], data.qpos[q0 + 2]);
        const Vec3 e_lin = pos - in.root_pos;
        const Vec3 e_ang =
            quat_log(in.root_quat.normalized().conjugate() * read_quat(data.qpos, b.qpos_adr + 3).normalized());
        for (size_t k = 0; k < 3; ++k) {
          const auto ke = static_cast<Eigen::Index>(k);
          data.law_kp[d0 + k] = finite(s.kp_lin) ? std::max(s.kp_lin, 0.0) : 0.0;
          data.law_kd[d0 + k] = finite(s.kd_lin) ? std::max(s.kd_lin, 0.0) : 0.0;
          data.law_kp[d0 + 3 + k] = finite(s.kp_ang) ? std::max(s.kp_ang, 0.0) : 0.0;
          data.law_kd[d0 + 3 + k] = finite(s.kd_ang) ? std::max(s.kd_ang, 0.0) : 0.0;
          data.err_dof[d0 + k] = e_lin(ke);
          data.err_dof[d0 + 3 + k] = e_ang(ke);
          data.vref_dof[d0 + k] = in.root_lin_vel(ke);
          data.vref_dof[d0 + 3 + k] = in.root_ang_vel(ke);
        }
        continue;
      }
      case JointType::fixed: continue;
    }
    for (size_t k = 0; k < static_cast<size_t>(b.dof_num); ++k) {
      const size_t d = d0 + k;
      const double vref = in.target_qvel[d];
      data.law_kp[d] = has_target ? data.drive_kp[d] : 0.0;
      data.law_kd[d] = data.drive_kd[d];
      data.err_dof[d] = err(static_cast<Eigen::Index>(k));
      data.vref_dof[d] = finite(vref) ? vref : 0.0;
    }
  }
}

void drive_terms(const Model& model, Data& data, DriveScheme scheme) {
  const bool implicit = scheme == DriveScheme::implicit;
  const auto nv = static_cast<size_t>(model.nv);
  for (size_t d = 0; d < nv; ++d) {
    data.kp_dof[d] = implicit ? data.law_kp[d] : 0.0;
    data.kd_dof[d] = implicit ? data.law_kd[d] : 0.0;
    data.tau_fixed[d] = data.drive_ff[d];
    if (!implicit) {
      data.tau_fixed[d] += -data.law_kp[d] * data.err_dof[d] - data.law_kd[d] * (data.qvel[d] - data.vref_dof[d]);
    }
  }
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    if (b.joint != JointType::ball && b.joint != JointType::hinge) continue;
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const auto n = static_cast<size_t>(b.dof_num);
    if (implicit && data.drive_in_rows[i]) {
      // Solved as a bounded row: neither in the inertia nor as a fixed torque.
      for (size_t d = d0; d < d0 + n; ++d) data.kp_dof[d] = data.kd_dof[d] = data.tau_fixed[d] = 0.0;
      continue;
    }
    // Explicit drives are clamped here, once: their torque is known before the solve.
    const double limit = data.drive_limit[i];
    if (!implicit && limit > 0.0) {
      double norm2 = 0.0;
      for (size_t k = d0; k < d0 + n; ++k) norm2 += data.tau_fixed[k] * data.tau_fixed[k];
      const double norm = std::sqrt(norm2);
      if (norm > limit) {
        for (size_t k = d0; k < d0 + n; ++k) data.tau_fixed[k] *= limit / norm;
        data.drive_saturated[i] = true;
      }
    }
  }
}

void add_drive_rows(const Model& model, Data& data) {
  const double dt = model.timestep_s;
  data.nrows = data.nbase_rows;
  data.jac_used = data.jac_base_used;
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    if (!data.drive_in_rows[i]) continue;
    const Body& b = model.bodies[i];
    const auto d0 = static_cast<size_t>(b.dof_adr);
    // K' of the law per dof (a ball joint's axes may differ); every axis needs one.
    bool compliant = true;
    for (size_t d = d0; d < d0 + static_cast<size_t>(b.dof_num); ++d)
      compliant = compliant && data.law_kd[d] + dt * data.law_kp[d] > 0.0;
    const bool fits = data.nrows + b.dof_num <= static_cast<int>(kMaxRows) &&
                      data.njoint_rows + b.dof_num <= static_cast<int>(kMaxJointRows) &&
                      jacobian_fits(data, model.body_path_dofs[i], b.dof_num, kRowJacobianPool);
    if (!compliant || !fits) {
      // A constant feedforward alone, or no room: back to the inertia (unclamped, counted if for room).
      if (!fits) ++data.diag.limit_overflow;
      data.drive_in_rows[i] = false;
      for (size_t d = d0; d < d0 + static_cast<size_t>(b.dof_num); ++d) {
        data.kp_dof[d] = data.law_kp[d];
        data.kd_dof[d] = data.law_kd[d];
        data.tau_fixed[d] = data.drive_ff[d];
      }
      continue;
    }
    const int group = data.nrows;
    for (int k = 0; k < b.dof_num; ++k) {
      const size_t d = d0 + static_cast<size_t>(k);
      const double k_dof = data.law_kd[d] + dt * data.law_kp[d];
      Data::Row r;
      r.kind = Data::Row::Kind::drive;
      r.limit_body = static_cast<int>(i);
      r.limit_coef = Vec3::Unit(k);
      r.support = model.body_path_dofs[i];
      // tau = -K' (v+ - v*): the law rearranged around its velocity target.
      r.target = (data.law_kd[d] * data.vref_dof[d] - data.law_kp[d] * data.err_dof[d] + data.drive_ff[d]) / k_dof;
      r.cfm = 1.0 / (dt * k_dof);
      r.bound = data.drive_limit[i] * dt;
      r.group = group;
      r.lambda = data.drive_impulse[d];
      add_row(data, r);
      ++data.njoint_rows;
    }
  }
}

bool free_velocity(const Model& model, Data& data) {
  const int nv = model.nv;
  const int first = data.first_active_dof;
  const double dt = model.timestep_s;
  const auto unv = static_cast<size_t>(nv);
  // Copy the lower triangle on the simulated dofs' paths and add the drives.
  for (int k = first; k < nv; ++k) {
    for (int j = k; j >= first; j = model.dof_parent[static_cast<size_t>(j)]) {
      const auto at = static_cast<size_t>(k) * unv + static_cast<size_t>(j);
      data.factor[at] = data.mass[at];
    }
    const auto ku = static_cast<size_t>(k);
    data.factor[ku * unv + ku] += dt * data.kd_dof[ku] + dt * dt * data.kp_dof[ku];
  }
  if (!ltdl::factor(data.factor, nv, model.dof_parent, first)) return false;

  // Right-hand side: impulses of the explicit forces and the implicit drives'
  // start-of-step parts, minus what the prescribed root's velocity change takes.
  for (size_t k = 0; k < unv; ++k) {
    data.work[k] = dt * (data.tau_fixed[k] - data.bias[k] - data.kp_dof[k] * (data.err_dof[k] + dt * data.qvel[k]) -
                         data.kd_dof[k] * (data.qvel[k] - data.vref_dof[k]));
  }
  if (first > 0) {
    // work_a -= M_ap dv_p, with M_ap below the diagonal (prescribed dofs are everyone's ancestors).
    for (int k = first; k < nv; ++k) {
      double s = 0.0;
      for (int j = model.dof_parent[static_cast<size_t>(k)]; j >= 0; j = model.dof_parent[static_cast<size_t>(j)]) {
        if (j < first)
          s += data.mass[static_cast<size_t>(k) * unv + static_cast<size_t>(j)] * data.root_dv[static_cast<size_t>(j)];
      }
      data.work[static_cast<size_t>(k)] -= s;
    }
  }
  ltdl::solve(data.factor, nv, model.dof_parent, first, std::span<double>(data.work).first(unv));
  for (size_t k = 0; k < unv; ++k) {
    const bool prescribed = static_cast<int>(k) < first;
    data.qvel_free[k] = data.qvel[k] + (prescribed ? data.root_dv[k] : data.work[k]);
  }
  return true;
}

bool drive_torques(const Model& model, Data& data, DriveScheme scheme) {
  const double dt = model.timestep_s;
  const bool implicit = scheme == DriveScheme::implicit;
  const auto nv = static_cast<size_t>(model.nv);
  for (size_t d = 0; d < nv; ++d) {
    data.tau_ff[d] = data.drive_ff[d];
    if (implicit) {
      const double v_end = data.qvel_next[d];
      data.tau_pd[d] = -data.kp_dof[d] * (data.err_dof[d] + dt * v_end) - data.kd_dof[d] * (v_end - data.vref_dof[d]);
    } else {
      data.tau_pd[d] = data.tau_fixed[d] - data.drive_ff[d];  // clamped before the solve
    }
  }
  if (!implicit) return false;
  // Drive rows: their impulse is the torque applied.
  for (int r = data.nbase_rows; r < data.nrows; ++r) {
    const Data::Row& row = data.rows[static_cast<size_t>(r)];
    if (row.kind != Data::Row::Kind::drive) continue;
    const Body& b = model.bodies[static_cast<size_t>(row.limit_body)];
    const size_t d = static_cast<size_t>(b.dof_adr) + static_cast<size_t>(r - row.group);
    data.tau_pd[d] = row.lambda / dt - data.drive_ff[d];
    data.drive_impulse[d] = row.lambda;
  }
  bool changed = false;
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    if (b.joint != JointType::ball && b.joint != JointType::hinge) continue;
    const double limit = data.drive_limit[i];
    if (!(limit > 0.0)) continue;
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const auto n = static_cast<size_t>(b.dof_num);
    double norm2 = 0.0;
    for (size_t d = d0; d < d0 + n; ++d) {
      const double total = data.tau_pd[d] + data.tau_ff[d];
      norm2 += total * total;
    }
    const double norm = std::sqrt(norm2);
    if (data.drive_in_rows[i]) {
      data.drive_saturated[i] = norm >= limit * (1.0 - 1e-6);
    } else if (norm > limit * (1.0 + 1e-9)) {
      // Over the limit in the inertia: move it to the rows and redo the pass.
      data.drive_in_rows[i] = true;
      for (size_t d = d0; d < d0 + n; ++d)
        data.drive_impulse[d] = (data.tau_pd[d] + data.tau_ff[d]) * (limit / norm) * dt;
      changed = true;
    }
  }
  return changed;
}

void release_drive_rows(const Model& model, Data& data) {
  // Drives comfortably inside their limit go back to the exact factorisation
  // next step; the margin keeps a drive near its limit from flipping each step.
  constexpr double kRelease = 0.8;
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    if (!data.drive_in_rows[i]) continue;
    const Body& b = model.bodies[i];
    double norm2 = 0.0;
    for (size_t d = static_cast<size_t>(b.dof_adr); d < static_cast<size_t>(b.dof_adr) + static_cast<size_t>(b.dof_num);
         ++d) {
      const double total = data.tau_pd[d] + data.tau_ff[d];
      norm2 += total * total;
    }
    if (std::sqrt(norm2) < kRelease * data.drive_limit[i] || !(data.drive_limit[i] > 0.0))
      data.drive_in_rows[i] = false;
  }
}

}  // namespace tonus::sim::detail
