// ZMP preview control (see preview_control.hpp).
#include "tonus/host/balance/preview_control.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace tonus::balance {

PreviewModel preview_model(const PreviewOptions& o) {
  PreviewModel m;
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(o.dt_s) || !positive(o.com_height_m) || !positive(o.tracking_weight) || !positive(o.jerk_weight) ||
      !positive(o.gravity)) {
    m.error = "preview control: dt, centre-of-mass height, weights and gravity must be finite and positive";
    return m;
  }
  const double dt = o.dt_s;
  m.dt_s = dt;
  m.com_height_m = o.com_height_m;
  m.A << 1.0, dt, dt * dt / 2.0, 0.0, 1.0, dt, 0.0, 0.0, 1.0;
  m.B << dt * dt * dt / 6.0, dt * dt / 2.0, dt;
  m.C << 1.0, 0.0, -o.com_height_m / o.gravity;
  const double q = o.tracking_weight, r = o.jerk_weight;
  // The Riccati equation by iteration from P = C'QC (monotone for this
  // stabilisable and detectable pair), until it stops changing.
  Eigen::Matrix3d p = m.C.transpose() * q * m.C;
  constexpr int kMaxIterations = 200000;
  for (m.riccati_iterations = 0; m.riccati_iterations < kMaxIterations; ++m.riccati_iterations) {
    const double denom = r + m.B.dot(p * m.B);
    const Eigen::RowVector3d pba = m.B.transpose() * p * m.A;
    const Eigen::Matrix3d next = m.A.transpose() * p * m.A + m.C.transpose() * q * m.C - pba.transpose() * pba / denom;
    const double change = (next - p).norm();
    p = next;
    if (change <= 1e-13 * std::max(1.0, p.norm())) break;
  }
  if (m.riccati_iterations >= kMaxIterations || !p.allFinite()) {
    m.error = "preview control: the Riccati iteration did not converge";
    return m;
  }
  m.P = p;
  const double denom = r + m.B.dot(p * m.B);
  m.K = m.B.transpose() * p * m.A / denom;
  const Eigen::Matrix3d closed_t = (m.A - m.B * m.K).transpose();
  Eigen::Vector3d x = m.C.transpose() * q;  // ((A - BK)')^(j-1) C'Q
  const std::size_t n = std::max<std::size_t>(o.preview_frames, 1);
  m.preview.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    m.preview[j] = m.B.dot(x) / denom;
    x = closed_t * x;
  }
  // Beyond the preview the reference is held at its last value: the rest of
  // the series, sum_{j>N} ((A - BK)')^(j-1) C'Q = ((A - BK)')^N (I - (A - BK)')^-1 C'Q,
  // joins the last gain.
  const Eigen::Vector3d tail = (Eigen::Matrix3d::Identity() - closed_t).lu().solve(x);
  m.preview[n - 1] += m.B.dot(tail) / denom;
  return m;
}

double preview_step(const PreviewModel& m, Eigen::Vector3d& state, std::span<const double> ahead) {
  double u = -m.K.dot(state);
  if (!ahead.empty()) {
    // Fewer values than the preview: the last one is held.
    for (std::size_t j = 0; j < m.preview.size(); ++j) u += m.preview[j] * ahead[std::min(j, ahead.size() - 1)];
  }
  state = m.A * state + m.B * u;
  return u;
}

}  // namespace tonus::balance
