// ZMP preview control on the cart-table model (Kajita et al., "Biped walking
// pattern generation by using preview control of zero-moment point", ICRA
// 2003), the core of the streaming balance filter's look-ahead (issue 14).
//
// One horizontal axis: the centre of mass x driven by its jerk u, sampled
// every dt; the ZMP of a cart on a table of height z_c is
//   p = x - (z_c / g) xdd.
// With the state s = (x, xd, xdd): s' = A s + B u, p = C s. The jerk that
// minimises sum Q (p - r)^2 + R u^2 over an infinite horizon, knowing the
// reference r for the next N samples (and taking it as held at r_{k+N}
// beyond, so a constant reference is followed exactly), is
//   u_k = -K s_k + sum_{j=1..N} f_j r_{k+j},
// with P the stabilising solution of the discrete algebraic Riccati equation
//   P = A'PA + C'QC - A'PB (R + B'PB)^-1 B'PA,
//   K = (R + B'PB)^-1 B'PA,  f_j = (R + B'PB)^-1 B' ((A - BK)')^(j-1) C'Q,
// f_N also carrying the held tail, (R + B'PB)^-1 B' ((A - BK)')^N (I - (A - BK)')^-1 C'Q.
// The gains are computed once (the model); a step costs O(N) and allocates
// nothing.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace tonus::balance {

struct PreviewModel {
  double dt_s = 0.0;
  double com_height_m = 0.0;
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  Eigen::Vector3d B = Eigen::Vector3d::Zero();
  Eigen::RowVector3d C = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  // the Riccati solution
  Eigen::RowVector3d K = Eigen::RowVector3d::Zero();
  std::vector<double> preview;  // f_1 .. f_N
  int riccati_iterations = 0;
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

struct PreviewOptions {
  double dt_s = 1.0 / 120.0;
  double com_height_m = 0.9;
  std::size_t preview_frames = 30;  // N: how far ahead the reference is known (at least 1)
  double tracking_weight = 1.0;     // Q, per m^2 of ZMP error
  double jerk_weight = 1e-6;        // R, per (m/s^3)^2 (Kajita's ratio R / Q = 1e-6)
  double gravity = 9.81;
};

// Refuses (error) a dt, height, weight or gravity that is not finite and
// positive, and a Riccati iteration that does not converge.
PreviewModel preview_model(const PreviewOptions& options);

// The cart's ZMP for a state.
[[nodiscard]] inline double cart_zmp(const PreviewModel& m, const Eigen::Vector3d& s) { return m.C * s; }

// One step: the jerk from the state and the reference ahead (ahead[j - 1] is
// r_{k+j}; with fewer values than N the last is held, more are ignored, none
// regulates to zero), then the state advanced by it. Returns the jerk.
double preview_step(const PreviewModel& m, Eigen::Vector3d& state, std::span<const double> ahead);

}  // namespace tonus::balance
