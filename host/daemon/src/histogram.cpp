#include "tonus/host/daemon/histogram.hpp"

#include <algorithm>
#include <cmath>

namespace tonus::daemon {

Histogram::Histogram(double bin_us, std::size_t bins) : bin_us_(bin_us > 0.0 ? bin_us : 1.0), bins_(bins + 1, 0) {}

void Histogram::add(double value_us) {
  if (!std::isfinite(value_us) || value_us < 0.0) value_us = 0.0;
  const double b = std::floor(value_us / bin_us_);
  const std::size_t last = bins_.size() - 1;
  const std::size_t i = b >= static_cast<double>(last) ? last : static_cast<std::size_t>(b);
  ++bins_[i];
  ++count_;
  sum_us_ += value_us;
  max_us_ = std::max(max_us_, value_us);
}

void Histogram::clear() {
  std::fill(bins_.begin(), bins_.end(), 0);
  count_ = 0;
  sum_us_ = 0.0;
  max_us_ = 0.0;
}

double Histogram::quantile_us(double q) const {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  // The smallest bin whose cumulative count reaches ceil(q * n) (at least 1).
  const auto target =
      std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i + 1 < bins_.size(); ++i) {
    seen += bins_[i];
    if (seen >= target) return std::min(max_us_, static_cast<double>(i + 1) * bin_us_);
  }
  return max_us_;
}

std::uint64_t Histogram::count_above(double threshold_us) const {
  const auto first = static_cast<std::size_t>(std::max(0.0, std::ceil(threshold_us / bin_us_)));
  std::uint64_t n = 0;
  for (std::size_t i = std::min(first, bins_.size() - 1); i < bins_.size(); ++i) n += bins_[i];
  return n;
}

void Histogram::merge(const Histogram& other) {
  if (other.bins_.size() != bins_.size() || other.bin_us_ != bin_us_) return;
  for (std::size_t i = 0; i < bins_.size(); ++i) bins_[i] += other.bins_[i];
  count_ += other.count_;
  sum_us_ += other.sum_us_;
  max_us_ = std::max(max_us_, other.max_us_);
}

}  // namespace tonus::daemon
