#include "tonus/host/derivatives/white_jerk.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <numbers>

namespace tonus::derivatives {

WhiteJerkModel make_model(const Params& params, double dt_s) {
  WhiteJerkModel m;
  m.tau = 1.0 / (2.0 * std::numbers::pi * params.cutoff_hz);
  m.r = params.noise_sigma * params.noise_sigma;
  const double e = dt_s / m.tau;
  m.F << 1.0, e, 0.5 * e * e, 0.0, 1.0, e, 0.0, 0.0, 1.0;
  m.Finv << 1.0, -e, 0.5 * e * e, 0.0, 1.0, -e, 0.0, 0.0, 1.0;
  // q tau^5 = sigma^2 e when q comes from the cutoff (params.hpp).
  const double e2 = e * e, e3 = e2 * e, e4 = e3 * e, e5 = e4 * e;
  m.Q << e5 / 20.0, e4 / 8.0, e3 / 6.0, e4 / 8.0, e3 / 3.0, e2 / 2.0, e3 / 6.0, e2 / 2.0, e;
  m.Q *= m.r * e;
  return m;
}

namespace {
Eigen::Matrix3d symmetric(const Eigen::Matrix3d& a) { return 0.5 * (a + a.transpose()); }
}  // namespace

RtsLink WhiteJerkFilter::predict() {
  RtsLink link;
  if (!covariance_) {
    // Information form without Q^-1 (Y may be singular): with M = F^-T Y F^-1,
    //   Y+ = (I + M Q)^-1 M,  eta+ = (I + M Q)^-1 F^-T eta,
    //   C = F^-1 (I + Q M)^-1,  d = C Q F^-T eta  (docs/derivatives.md).
    const Eigen::Matrix3d M = symmetric(m_.Finv.transpose() * Y_ * m_.Finv);
    const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() + m_.Q * M;
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(A);
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu_t(A.transpose());
    const Eigen::Vector3d ft_eta = m_.Finv.transpose() * eta_;
    link.C = m_.Finv * lu.inverse();
    link.d = link.C * (m_.Q * ft_eta);
    Y_ = symmetric(lu_t.solve(M));
    eta_ = lu_t.solve(ft_eta);
    return link;
  }
  const Eigen::Vector3d x_pred = m_.F * x_;
  const Eigen::Matrix3d P_pred = symmetric(m_.F * P_ * m_.F.transpose() + m_.Q);
  // C = P F' P+^-1, i.e. C' = P+^-1 (F P).
  const Eigen::LLT<Eigen::Matrix3d> llt(P_pred);
  link.C = llt.solve(m_.F * P_).transpose();
  link.d = x_ - link.C * x_pred;
  x_ = x_pred;
  P_ = P_pred;
  return link;
}

WhiteJerkFilter::Update WhiteJerkFilter::update(double y) {
  if (!std::isfinite(y)) return Update::missing;
  if (!covariance_) {
    Y_(0, 0) += 1.0 / m_.r;
    eta_[0] += y / m_.r;
    if (++used_ >= kMinFiniteSamples) {
      // Enough information for a proper state: switch to covariance form.
      const Eigen::LLT<Eigen::Matrix3d> llt(Y_);
      if (llt.info() == Eigen::Success) {
        P_ = symmetric(llt.solve(Eigen::Matrix3d::Identity()));
        x_ = llt.solve(eta_);
        covariance_ = true;
      }
    }
    return Update::used;
  }
  const double innovation = y - x_[0];
  const double s = P_(0, 0) + m_.r;
  if (gate_ > 0.0 && std::abs(innovation) > gate_ * std::sqrt(s) && gated_run_ < kMaxGatedRun) {
    ++gated_run_;
    return Update::rejected;
  }
  gated_run_ = 0;
  const Eigen::Vector3d k = P_.col(0) / s;
  x_ += k * innovation;
  P_ = symmetric(P_ - k * k.transpose() * s);
  ++used_;
  return Update::used;
}

}  // namespace tonus::derivatives
