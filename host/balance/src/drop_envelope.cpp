#include "drop_envelope.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tonus::balance::detail {

DropEnvelope::DropEnvelope(double dt_s, std::size_t max_reach_frames) {
  const std::size_t cap = std::min(max_reach_frames, kMaxReach);
  const double dt = dt_s > 0.0 && std::isfinite(dt_s) ? dt_s : 1.0 / 30.0;
  const double sigma = kDropSmoothing_s / dt;  // frames
  blur_ = std::min(static_cast<std::size_t>(std::ceil(3.0 * sigma)), cap / 2);
  ease_ = std::min(static_cast<std::size_t>(std::lround(kDropEase_s / dt)), cap - blur_);
  // The cosine reaches zero one frame past its half width.
  const double span = static_cast<double>(ease_ + 1);
  for (std::size_t j = 0; j <= ease_; ++j)
    cosine_[j] = 0.5 * (1.0 + std::cos(std::numbers::pi * static_cast<double>(j) / span));
  double total = 0.0;
  for (std::size_t u = 0; u <= blur_; ++u) {
    gauss_[u] = sigma > 0.0 ? std::exp(-0.5 * static_cast<double>(u * u) / (sigma * sigma)) : (u == 0 ? 1.0 : 0.0);
    total += u == 0 ? gauss_[u] : 2.0 * gauss_[u];
  }
  double peak = 0.0;
  for (std::size_t u = 0; u <= blur_; ++u) {
    gauss_[u] /= total;
    const double c = u <= ease_ ? cosine_[u] : 0.0;
    peak += (u == 0 ? 1.0 : 2.0) * gauss_[u] * c;
  }
  raise_ = peak > 0.0 ? 1.0 / peak : 1.0;
}

double DropEnvelope::spread(const double* need, std::ptrdiff_t count, std::ptrdiff_t j) const {
  const auto ease = static_cast<std::ptrdiff_t>(ease_);
  double envelope = 0.0;
  for (std::ptrdiff_t s = std::max<std::ptrdiff_t>(j - ease, 0); s <= std::min(j + ease, count - 1); ++s) {
    if (need[s] > 0.0) envelope = std::max(envelope, need[s] * cosine_[static_cast<std::size_t>(std::abs(s - j))]);
  }
  return envelope;
}

double DropEnvelope::at(const double* need, std::size_t count, std::size_t t) const {
  const auto n = static_cast<std::ptrdiff_t>(count);
  const auto blur = static_cast<std::ptrdiff_t>(blur_);
  const auto tt = static_cast<std::ptrdiff_t>(t);
  double sum = 0.0;
  for (std::ptrdiff_t u = -blur; u <= blur; ++u)
    sum += gauss_[static_cast<std::size_t>(std::abs(u))] * spread(need, n, tt + u);
  return raise_ * sum;
}

std::vector<double> DropEnvelope::smooth(const std::vector<double>& need) const {
  // at() for every frame, in two passes (the envelope once per frame, then
  // the Gaussian over it) rather than the envelope again for each of its
  // neighbours: the same sums in the same order.
  const auto n = static_cast<std::ptrdiff_t>(need.size());
  const auto blur = static_cast<std::ptrdiff_t>(blur_);
  std::vector<double> envelope(need.size() + 2 * blur_, 0.0);  // frames -blur .. n - 1 + blur
  for (std::ptrdiff_t j = -blur; j < n + blur; ++j)
    envelope[static_cast<std::size_t>(j + blur)] = spread(need.data(), n, j);
  std::vector<double> out(need.size(), 0.0);
  for (std::ptrdiff_t t = 0; t < n; ++t) {
    double sum = 0.0;
    for (std::ptrdiff_t u = -blur; u <= blur; ++u)
      sum += gauss_[static_cast<std::size_t>(std::abs(u))] * envelope[static_cast<std::size_t>(t + u + blur)];
    out[static_cast<std::size_t>(t)] = raise_ * sum;
  }
  return out;
}

}  // namespace tonus::balance::detail
