#include "tonus/host/derivatives/fixed_lag.hpp"

#include <algorithm>

namespace tonus::derivatives {

FixedLag::Created FixedLag::create(double dt_s, const Params& params, std::size_t lag) {
  Created c;
  c.status = validate(params, dt_s, kMinSamples);
  if (c.status && params.method != Method::kalman && params.method != Method::kalman_spline) {
    c.status = {Error::bad_method, 0};
  }
  if (c.status && lag > kMaxLag) c.status = {Error::bad_lag, lag};
  if (!c.status) return c;
  FixedLag f;
  f.lag_ = lag;
  f.filter_ = WhiteJerkFilter(make_model(params, dt_s), params.outlier_gate);
  c.smoother = f;
  return c;
}

Estimate FixedLag::push(double x) {
  if (pushed_ > 0) links_[(pushed_ - 1) % kMaxLag] = filter_.predict();
  switch (filter_.update(x)) {
    case WhiteJerkFilter::Update::missing: ++missing_; break;
    case WhiteJerkFilter::Update::rejected: ++rejected_; break;
    case WhiteJerkFilter::Update::used: break;
  }
  ++pushed_;
  return estimate(lag_);
}

Estimate FixedLag::estimate(std::size_t frames_back) const {
  Estimate e;
  if (frames_back > lag_ || frames_back >= pushed_ || !filter_.ready()) return e;
  // The RTS backward pass from the filtered state of the newest sample.
  Eigen::Vector3d s = filter_.state();
  const std::size_t newest = pushed_ - 1;
  for (std::size_t j = 1; j <= frames_back; ++j) {
    const RtsLink& link = links_[(newest - j) % kMaxLag];
    s = link.C * s + link.d;
  }
  const Eigen::Vector3d u = filter_.unscale(s);
  e.valid = true;
  e.index = newest - frames_back;
  e.pos = u[0];
  e.vel = u[1];
  e.acc = u[2];
  return e;
}

void FixedLag::estimate_window(std::span<Estimate> out) const {
  for (Estimate& e : out) e = Estimate{};
  if (out.empty() || pushed_ == 0 || !filter_.ready()) return;
  const std::size_t newest = pushed_ - 1;
  const std::size_t deepest = std::min({out.size() - 1, lag_, newest});
  Eigen::Vector3d s = filter_.state();
  for (std::size_t j = 0; j <= deepest; ++j) {
    if (j > 0) {
      const RtsLink& link = links_[(newest - j) % kMaxLag];
      s = link.C * s + link.d;
    }
    const Eigen::Vector3d u = filter_.unscale(s);
    out[j].valid = true;
    out[j].index = newest - j;
    out[j].pos = u[0];
    out[j].vel = u[1];
    out[j].acc = u[2];
  }
}

void FixedLag::reset() {
  filter_.reset();
  pushed_ = 0;
  missing_ = 0;
  rejected_ = 0;
}

FixedLag3::Created FixedLag3::create(double dt_s, const Params& params, std::size_t lag) {
  Created c;
  FixedLag::Created one = FixedLag::create(dt_s, params, lag);
  c.status = one.status;
  if (one.smoother) c.smoother = FixedLag3(*one.smoother);
  return c;
}

namespace {
Estimate3 combine(const Estimate& x, const Estimate& y, const Estimate& z) {
  Estimate3 e;
  e.valid = x.valid && y.valid && z.valid;
  e.index = x.index;
  e.pos = {x.pos, y.pos, z.pos};
  e.vel = {x.vel, y.vel, z.vel};
  e.acc = {x.acc, y.acc, z.acc};
  return e;
}
}  // namespace

Estimate3 FixedLag3::push(const Eigen::Vector3d& x) {
  const Estimate a = axes_[0].push(x[0]);
  const Estimate b = axes_[1].push(x[1]);
  const Estimate c = axes_[2].push(x[2]);
  return combine(a, b, c);
}

Estimate3 FixedLag3::estimate(std::size_t frames_back) const {
  return combine(axes_[0].estimate(frames_back), axes_[1].estimate(frames_back), axes_[2].estimate(frames_back));
}

void FixedLag3::estimate_window(std::span<Estimate3> out) const {
  std::array<std::array<Estimate, FixedLag::kMaxLag + 1>, 3> axis{};
  const std::size_t n = std::min(out.size(), FixedLag::kMaxLag + 1);
  for (std::size_t c = 0; c < 3; ++c) axes_[c].estimate_window(std::span<Estimate>(axis[c].data(), n));
  for (std::size_t j = 0; j < out.size(); ++j) {
    out[j] = j < n ? combine(axis[0][j], axis[1][j], axis[2][j]) : Estimate3{};
  }
}

void FixedLag3::reset() {
  for (FixedLag& a : axes_) a.reset();
}

}  // namespace tonus::derivatives
