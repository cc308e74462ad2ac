// The constant-acceleration (white-jerk) Kalman filter that the batch smoother
// and FixedLag share, with the links of its RTS backward pass.
//
// State s = [p, v tau, a tau^2] with tau = 1 / (2 pi f_c): scaling time by the
// smoother's own time constant keeps the covariance balanced (its entries are
// all about sigma^2 * 2 pi f_c dt) over the whole accepted range of f_c dt.
// With e = dt / tau:
//   F = [[1, e, e^2/2], [0, 1, e], [0, 0, 1]],
//   Q = q tau^5 [[e^5/20, e^4/8, e^3/6], [e^4/8, e^3/3, e^2/2], [e^3/6, e^2/2, e]],  R = sigma^2.
//
// The prior on the first state is flat (no information), so the smoother is the
// exact maximum a posteriori estimate of the model given the samples alone.
// The filter runs in information form (Y = P^-1, eta = Y s) until it has seen
// 3 finite samples, using forms that stay finite when Y is singular, then in
// covariance form. Either way each prediction from step k to k + 1 yields the
// affine link of the RTS backward pass
//   s_k|N = C_k s_k+1|N + d_k,   C_k = P_k F' P_k+1|k^-1,   d_k = s_k|k - C_k F s_k|k.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "tonus/host/derivatives/params.hpp"

namespace tonus::derivatives {

struct WhiteJerkModel {
  double tau = 1.0;  // s
  double r = 1.0;    // sigma^2
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d Finv = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
};
// The model for validated params (validate() first).
WhiteJerkModel make_model(const Params& params, double dt_s);

// One link of the backward pass: s_k|N = C s_k+1|N + d.
struct RtsLink {
  Eigen::Matrix3d C = Eigen::Matrix3d::Identity();
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
};

class WhiteJerkFilter {
 public:
  enum class Update : std::uint8_t { used, missing, rejected };

  WhiteJerkFilter() = default;
  WhiteJerkFilter(const WhiteJerkModel& model, double outlier_gate) : m_(model), gate_(outlier_gate) {}

  // Back to no samples seen (keeps the model and the gate).
  void reset() { *this = WhiteJerkFilter(m_, gate_); }

  // Prediction from the current step to the next; returns the current step's link.
  RtsLink predict();
  // Measurement update with the sample of the current step (NaN/inf = missing).
  Update update(double y);

  // True once the filtered state is defined (3 finite samples used).
  [[nodiscard]] bool ready() const { return covariance_; }
  // Filtered state of the current step (scaled; valid when ready()).
  [[nodiscard]] const Eigen::Vector3d& state() const { return x_; }
  [[nodiscard]] const Eigen::Matrix3d& covariance() const { return P_; }
  [[nodiscard]] const WhiteJerkModel& model() const { return m_; }

  // Physical position, velocity, acceleration of a scaled state.
  [[nodiscard]] Eigen::Vector3d unscale(const Eigen::Vector3d& s) const {
    return {s[0], s[1] / m_.tau, s[2] / (m_.tau * m_.tau)};
  }

 private:
  WhiteJerkModel m_;
  double gate_ = 0.0;
  Eigen::Matrix3d Y_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d eta_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d P_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();
  bool covariance_ = false;
  std::size_t used_ = 0;       // finite samples used so far
  std::size_t gated_run_ = 0;  // consecutive samples rejected by the gate
};

}  // namespace tonus::derivatives
