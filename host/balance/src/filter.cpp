// Gauss-Newton over the waist corrections of all frames (see filter.hpp).
#include "tonus/host/balance/filter.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>

#include "accel_operator.hpp"
#include "tonus/host/balance/zmp.hpp"
#include "zmp_partials.hpp"

namespace tonus::balance {
namespace {

using detail::AccelOperator;
using detail::ZmpPartials;

// ZMP-equivalent scales: what one radian of correction, or one rad/s^2 of its
// angular acceleration, moves the ZMP by, roughly, for an adult (the upper
// body's mass share times its lever, and that times its height over g).
constexpr double kSizeScale_m = 0.2;
constexpr double kAccelScale_m = 0.02;

struct Targets {
  std::vector<bool> active;
  std::vector<Vec2> target;
};

HumanMotion corrected_motion(const HumanMotion& m, const std::vector<Vec3>& delta, std::vector<bool>& unreachable,
                             double* max_drop = nullptr) {
  HumanMotion out = m;  // (frames before first_frame stay as they are)
  unreachable.assign(m.size(), false);
  for (std::size_t t = m.first_frame; t < m.size(); ++t) {
    double drop = 0.0;
    bool reachable = true;
    out.frames[t] = rotate_waist(m.frames[t], delta[t], &drop, &reachable);
    unreachable[t] = !reachable;
    if (max_drop != nullptr) *max_drop = std::max(*max_drop, std::abs(drop));
  }
  return out;
}

Targets choose_targets(const Analysis& a, double margin) {
  Targets t;
  t.active.assign(a.frames.size(), false);
  t.target.assign(a.frames.size(), Vec2::Zero());
  for (std::size_t k = 0; k < a.frames.size(); ++k) {
    const FrameAnalysis& f = a.frames[k];
    if (!f.analysed || f.airborne || !f.zmp_defined) continue;
    if (f.outside_m <= -margin) continue;  // comfortably inside: no term
    t.active[k] = true;
    t.target[k] = nearest_point_inset(f.support, f.zmp, margin);
  }
  return t;
}

double objective(const Analysis& a, const Targets& t, const std::vector<Vec3>& delta, std::size_t first, double dt,
                 const FilterOptions& o, const std::vector<double>& weight) {
  double cost = 0.0;
  for (std::size_t k = first; k < a.frames.size(); ++k) {
    if (t.active[k]) cost += weight[k] * (a.frames[k].zmp - t.target[k]).squaredNorm();
    cost += std::pow(o.size_weight * kSizeScale_m, 2) * delta[k].squaredNorm();
    if (k > first && k + 1 < a.frames.size()) {
      const Vec3 acc = (delta[k - 1] - 2.0 * delta[k] + delta[k + 1]) / (dt * dt);
      cost += std::pow(o.smoothness * kAccelScale_m, 2) * acc.squaredNorm();
    }
  }
  return cost;
}

std::size_t count_outside(const Analysis& a, double tol) {
  std::size_t n = 0;
  for (const FrameAnalysis& f : a.frames) n += f.analysed && !f.airborne && f.zmp_defined && f.outside_m > tol ? 1 : 0;
  return n;
}

}  // namespace

FilterResult balance_filter(const HumanMotion& motion, const FilterOptions& o, FilterProgress progress, void* user) {
  FilterResult r;
  const std::size_t n = motion.size(), first = motion.first_frame;
  const double dt = motion.dt_s;
  r.before = analyse(motion, o.analysis);
  if (!r.before.ok()) {
    r.error = r.before.error;
    return r;
  }
  const ContactTrack& contacts = r.before.contacts;  // the feet do not move: neither do their contacts
  r.correction.assign(n, Vec3::Zero());
  Analysis now = r.before;
  std::vector<bool> unreachable(n, false);
  const double tol = o.analysis.tolerance_m;
  const std::size_t m = n - first;
  const AccelOperator op = detail::accel_operator(m, dt, o.analysis.derivatives);
  r.operator_band = op.band;
  std::vector<double> weight(n, 1.0);  // grows for frames that stay outside (penalty continuation)
  double damping = 1e-6;               // Levenberg-Marquardt

  for (r.iterations = 0; r.iterations < o.max_iterations; ++r.iterations) {
    const std::size_t outside = count_outside(now, tol);
    if (progress != nullptr) progress(r.iterations, outside, user);
    if (outside == 0) break;
    const Targets targets = choose_targets(now, o.margin_m);
    for (std::size_t k = first; k < n; ++k) {
      const FrameAnalysis& f = now.frames[k];
      if (targets.active[k] && f.outside_m > tol) weight[k] = std::min(weight[k] * 2.0, 1e4);
    }

    // Derivatives of every frame's segment positions with respect to its own
    // correction (numerically: the turn and the leg IK are cheap).
    using Triplet = Eigen::Triplet<double>;
    std::vector<Triplet> jac;
    std::vector<double> residual;
    std::size_t row = 0;
    const double h = 1e-6;
    std::vector<std::array<Vec3, kSegmentParts>> dcom(3 * m);
    for (std::size_t k = first; k < n; ++k) {
      const SegmentFrame& base = now.segments[k];
      for (int e = 0; e < 3; ++e) {
        Vec3 d = r.correction[k];
        d(e) += h;
        const SegmentFrame moved = place_segments(now.mass, rotate_waist(motion.frames[k], d).p);
        const std::size_t idx = 3 * (k - first) + static_cast<std::size_t>(e);
        for (std::size_t i = 0; i < kSegmentParts; ++i) dcom[idx][i] = (moved[i].com - base[i].com) / h;
      }
    }
    // ZMP residuals: a frame's ZMP moves with its own correction (its
    // segments) and with every correction within the operator's band (its accelerations).
    for (std::size_t k = first; k < n; ++k) {
      if (!targets.active[k]) continue;
      const double sw = std::sqrt(weight[k]);
      const Vec2 res = sw * (now.frames[k].zmp - targets.target[k]);
      for (int c = 0; c < 2; ++c) residual.push_back(res(c));
      const ZmpPartials dp = detail::zmp_partials(now.mass, now.segments[k], now.accelerations[k], now.frames[k].zmp,
                                                  contacts.ground_z_m, o.analysis.gravity);
      const std::size_t kk = k - first;
      const std::size_t lo = kk > op.band ? kk - op.band : 0, hi = std::min(m - 1, kk + op.band);
      for (std::size_t jj = lo; jj <= hi; ++jj) {
        const double w = op.at(kk, jj);
        for (int e = 0; e < 3; ++e) {
          const auto& dc = dcom[3 * jj + static_cast<std::size_t>(e)];
          Vec2 dz = Vec2::Zero();
          for (std::size_t i = 0; i < kSegmentParts; ++i) {
            dz += w * (dp.dacc[i] * dc[i]);
            if (jj == kk) dz += dp.dpos[i] * dc[i];
          }
          const auto col = static_cast<int>(3 * jj + static_cast<std::size_t>(e));
          for (int c = 0; c < 2; ++c) jac.emplace_back(static_cast<int>(row) + c, col, sw * dz(c));
        }
      }
      row += 2;
    }
    // Normal equations: J^T J + smoothness (second difference) + size + damping.
    const auto unknowns = static_cast<Eigen::Index>(3 * m);
    Eigen::SparseMatrix<double> j_mat(static_cast<Eigen::Index>(row), unknowns);
    j_mat.setFromTriplets(jac.begin(), jac.end());
    Eigen::SparseMatrix<double> hess = j_mat.transpose() * j_mat;
    Eigen::VectorXd rhs =
        -(j_mat.transpose() * Eigen::Map<const Eigen::VectorXd>(residual.data(), static_cast<Eigen::Index>(row)));
    std::vector<Triplet> reg;
    const double ws = std::pow(o.smoothness * kAccelScale_m / (dt * dt), 2);
    const double wr = std::pow(o.size_weight * kSizeScale_m, 2);
    for (std::size_t k = 0; k < m; ++k) {
      for (int e = 0; e < 3; ++e) {
        const auto i = static_cast<int>(3 * k + static_cast<std::size_t>(e));
        reg.emplace_back(i, i, wr);
        rhs(i) -= wr * r.correction[first + k](e);
      }
    }
    for (std::size_t k = 1; k + 1 < m; ++k) {  // second difference over (k-1, k, k+1)
      const double coef[3] = {1.0, -2.0, 1.0};
      for (int e = 0; e < 3; ++e) {
        double d2 = 0.0;
        for (std::size_t a = 0; a < 3; ++a) d2 += coef[a] * r.correction[first + k - 1 + a](e);
        for (std::size_t a = 0; a < 3; ++a) {
          const auto ia = static_cast<int>(3 * (k - 1 + a) + static_cast<std::size_t>(e));
          rhs(ia) -= ws * coef[a] * d2;
          for (std::size_t b = 0; b < 3; ++b) {
            reg.emplace_back(ia, static_cast<int>(3 * (k - 1 + b) + static_cast<std::size_t>(e)),
                             ws * coef[a] * coef[b]);
          }
        }
      }
    }
    Eigen::SparseMatrix<double> reg_mat(unknowns, unknowns);
    reg_mat.setFromTriplets(reg.begin(), reg.end());
    hess += reg_mat;

    // Levenberg-Marquardt: a failed step raises the damping and tries again.
    // A frame whose legs cannot reach their feet costs as much as a metre of ZMP
    // error: steps into it are refused, so a foot is never moved by the filter
    // unless the captured pose already forces it.
    const auto cost_of = [&](const Analysis& a, const std::vector<Vec3>& delta, const std::vector<bool>& out_of_reach) {
      double c = objective(a, targets, delta, first, dt, o, weight);
      for (std::size_t k = first; k < n; ++k) c += out_of_reach[k] ? 1.0 : 0.0;
      return c;
    };
    const double cost0 = cost_of(now, r.correction, unreachable);
    bool accepted = false;
    for (int attempt = 0; attempt < 8 && !accepted; ++attempt) {
      Eigen::SparseMatrix<double> damped = hess;
      for (Eigen::Index i = 0; i < unknowns; ++i) damped.coeffRef(i, i) += damping * (1.0 + hess.coeff(i, i));
      // Airborne frames are left uncorrected: their unknowns are pinned at zero
      // (a turn in flight would bend the ballistic path of the centre of mass).
      Eigen::VectorXd b = rhs;
      std::vector<bool> pinned(static_cast<std::size_t>(unknowns), false);
      for (std::size_t k = 0; k < m; ++k) {
        if (!r.before.frames[first + k].airborne) continue;
        for (std::size_t e = 0; e < 3; ++e) pinned[3 * k + e] = true;
      }
      damped.prune([&pinned](Eigen::Index i, Eigen::Index j, double) {
        return i == j || (!pinned[static_cast<std::size_t>(i)] && !pinned[static_cast<std::size_t>(j)]);
      });
      for (Eigen::Index i = 0; i < unknowns; ++i) {
        if (!pinned[static_cast<std::size_t>(i)]) continue;
        damped.coeffRef(i, i) = 1.0;
        b(i) = 0.0;
      }
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        damping *= 10.0;
        continue;
      }
      const Eigen::VectorXd step = solver.solve(b);
      std::vector<Vec3> trial = r.correction;
      for (std::size_t k = 0; k < m; ++k) {
        Vec3 d = trial[first + k] + step.segment<3>(static_cast<Eigen::Index>(3 * k));
        if (d.norm() > o.max_correction_rad) d *= o.max_correction_rad / d.norm();
        trial[first + k] = d;
      }
      std::vector<bool> cand_unreachable;
      HumanMotion cand = corrected_motion(motion, trial, cand_unreachable);
      Analysis ca = analyse(cand, o.analysis, &contacts);
      if (ca.ok() && cost_of(ca, trial, cand_unreachable) < cost0) {
        unreachable = std::move(cand_unreachable);
        r.correction = std::move(trial);
        now = std::move(ca);
        accepted = true;
        damping = std::max(damping / 3.0, 1e-9);
      } else {
        damping *= 10.0;
      }
    }
    if (!accepted) break;  // no step lowers the cost: as good as it gets
  }

  r.corrected = corrected_motion(motion, r.correction, unreachable, &r.max_drop_m);
  r.after = analyse(r.corrected, o.analysis, &contacts);
  r.unsolved.assign(n, false);
  for (std::size_t k = first; k < n; ++k) {
    const FrameAnalysis& f = r.after.frames[k];
    const bool outside = f.analysed && !f.airborne && f.zmp_defined && f.outside_m > tol;
    const bool at_limit = r.correction[k].norm() >= o.max_correction_rad * (1.0 - 1e-9);
    r.unsolved[k] = outside || (at_limit && f.outside_m > -o.margin_m) || unreachable[k];
    r.frames_unsolved += r.unsolved[k] ? 1U : 0U;
    for (const Foot foot : {Foot::left, Foot::right}) {
      const FootLandmarks fl = foot_landmarks(foot);
      for (const Landmark l : {fl.ankle, fl.toe_joint, fl.toe_tip, fl.heel}) {
        r.max_foot_displacement_m = std::max(r.max_foot_displacement_m,
                                             (r.corrected.frames[k].p[index(l)] - motion.frames[k].p[index(l)]).norm());
      }
    }
  }
  return r;
}

}  // namespace tonus::balance
