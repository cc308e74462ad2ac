// The PD drives and the root servo. Implicit drives fold Kp and Kd into the
// joint-space inertia, so the torque is the one the end-of-step state calls
// for: (M + dt Kd + dt^2 Kp) dv = dt (tau - c - Kp (e + dt v) - Kd (v - vref)).
// A drive over its torque limit becomes an explicit, clamped torque and the
// pass is redone (an active set, at most solver.torque_limit_passes times).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "ltdl.hpp"
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
  for (size_t i = 0; i < nbody; ++i) {
    data.drive_kp[i] = gain_or_zero(in.kp[i], bad);
    data.drive_kd[i] = gain_or_zero(in.kd[i], bad);
    data.drive_limit[i] = gain_or_zero(in.torque_limit_nm[i], bad);
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

void drive_terms(const Model& model, Data& data, const StepInputs& in, DriveScheme scheme) {
  const bool implicit = scheme == DriveScheme::implicit;
  const auto nv = static_cast<size_t>(model.nv);
  std::fill_n(data.kp_dof.begin(), nv, 0.0);
  std::fill_n(data.kd_dof.begin(), nv, 0.0);
  std::fill_n(data.err_dof.begin(), nv, 0.0);
  std::fill_n(data.vref_dof.begin(), nv, 0.0);
  for (size_t d = 0; d < nv; ++d) data.tau_fixed[d] = data.drive_ff[d];

  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const auto q0 = static_cast<size_t>(b.qpos_adr);
    Vec3 err = Vec3::Zero();
    double kp = data.drive_kp[i], kd = data.drive_kd[i];
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
          kp = 0.0;  // no usable target: the drive only damps
        }
        break;
      }
      case JointType::free: {
        // The root servo, in free mode only.
        const RootServo& s = in.root_servo;
        const bool usable = s.enabled && data.root_mode == RootMode::free && all_finite(in.root_pos) &&
                            all_finite(in.root_lin_vel) && all_finite(in.root_ang_vel) && in.root_quat.norm() > 0.5;
        if (!usable) continue;
        const Vec3 pos(data.qpos[q0], data.qpos[q0 + 1], data.qpos[q0 + 2]);
        const Vec3 e_lin = pos - in.root_pos;
        const Vec3 e_ang =
            quat_log(in.root_quat.normalized().conjugate() * read_quat(data.qpos, b.qpos_adr + 3).normalized());
        for (size_t k = 0; k < 3; ++k) {
          const auto ke = static_cast<Eigen::Index>(k);
          data.kp_dof[d0 + k] = finite(s.kp_lin) ? std::max(s.kp_lin, 0.0) : 0.0;
          data.kd_dof[d0 + k] = finite(s.kd_lin) ? std::max(s.kd_lin, 0.0) : 0.0;
          data.kp_dof[d0 + 3 + k] = finite(s.kp_ang) ? std::max(s.kp_ang, 0.0) : 0.0;
          data.kd_dof[d0 + 3 + k] = finite(s.kd_ang) ? std::max(s.kd_ang, 0.0) : 0.0;
          data.err_dof[d0 + k] = e_lin(ke);
          data.err_dof[d0 + 3 + k] = e_ang(ke);
          data.vref_dof[d0 + k] = in.root_lin_vel(ke);
          data.vref_dof[d0 + 3 + k] = in.root_ang_vel(ke);
        }
        if (!implicit) {
          for (size_t k = d0; k < d0 + 6; ++k) {
            data.tau_fixed[k] += -data.kp_dof[k] * data.err_dof[k] - data.kd_dof[k] * (data.qvel[k] - data.vref_dof[k]);
            data.kp_dof[k] = data.kd_dof[k] = 0.0;
          }
        }
        continue;
      }
      case JointType::fixed: continue;
    }
    const auto n = static_cast<size_t>(b.dof_num);
    for (size_t k = 0; k < n; ++k) {
      const size_t d = d0 + k;
      const double vref = in.target_qvel[d];
      data.err_dof[d] = err(static_cast<Eigen::Index>(k));
      data.vref_dof[d] = finite(vref) ? vref : 0.0;
      if (data.drive_saturated[i]) {
        data.tau_fixed[d] = data.sat_torque[d];
      } else if (implicit) {
        data.kp_dof[d] = kp;
        data.kd_dof[d] = kd;
      } else {
        data.tau_fixed[d] += -kp * data.err_dof[d] - kd * (data.qvel[d] - data.vref_dof[d]);
      }
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
  bool changed = false;
  const auto nv = static_cast<size_t>(model.nv);
  for (size_t d = 0; d < nv; ++d) {
    // Implicit: at the end-of-step state; explicit: already in tau_fixed.
    const double v_end = data.qvel_next[d];
    data.tau_pd[d] = -data.kp_dof[d] * (data.err_dof[d] + dt * v_end) - data.kd_dof[d] * (v_end - data.vref_dof[d]);
    data.tau_ff[d] = data.drive_ff[d];
  }
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const auto n = static_cast<size_t>(b.dof_num);
    if (!implicit) {
      for (size_t k = d0; k < d0 + n; ++k) data.tau_pd[k] = data.tau_fixed[k] - data.drive_ff[k];
      continue;  // explicit drives were clamped before the solve
    }
    if (b.joint != JointType::ball && b.joint != JointType::hinge) continue;
    const double limit = data.drive_limit[i];
    if (!(limit > 0.0)) continue;
    // The drive's law at the end-of-step state, whether or not it is saturated
    // now: the joint is saturated exactly when this exceeds the limit.
    std::array<double, 3> law{};
    double norm2 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const size_t d = d0 + k;
      const double v_end = data.qvel_next[d];
      law[k] = -data.drive_kp[i] * (data.err_dof[d] + dt * v_end) - data.drive_kd[i] * (v_end - data.vref_dof[d]) +
               data.drive_ff[d];
      norm2 += law[k] * law[k];
    }
    const double norm = std::sqrt(norm2);
    const bool over = norm > limit * (1.0 + 1e-9);
    if (data.drive_saturated[i]) {
      for (size_t k = d0; k < d0 + n; ++k) data.tau_pd[k] = data.sat_torque[k] - data.drive_ff[k];
      if (!over) {  // the limit no longer binds: back to the implicit law
        data.drive_saturated[i] = false;
        changed = true;
        continue;
      }
      // Still saturated: follow the law's direction if it turned.
      double turn = 0.0;
      for (size_t k = 0; k < n; ++k) {
        const double next = law[k] * limit / norm;
        turn = std::max(turn, std::abs(next - data.sat_torque[d0 + k]));
        data.sat_torque[d0 + k] = next;
      }
      if (turn > 1e-6 * limit) changed = true;
      continue;
    }
    if (!over) continue;
    for (size_t k = 0; k < n; ++k) data.sat_torque[d0 + k] = law[k] * limit / norm;
    data.drive_saturated[i] = true;
    changed = true;
  }
  return changed && implicit;
}

}  // namespace tonus::sim::detail
