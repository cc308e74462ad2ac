#include "tonus/host/vmc/rate_limiter.hpp"

#include <algorithm>
#include <cmath>

namespace tonus::vmc {

std::string RateLimiter::validate(double hz) {
  if (!std::isfinite(hz) || hz < kMinHz || hz > kMaxHz) {
    return "VMC send rate must be 1 to 200 Hz (SlimeVR caps at 200 Hz \"to not crash VSF\")";
  }
  return {};
}

RateLimiter::RateLimiter(double hz) : hz_(std::isnan(hz) ? kDefaultHz : std::clamp(hz, kMinHz, kMaxHz)) {
  period_us_ = std::llround(1e6 / hz_);
}

bool RateLimiter::due(std::int64_t now_us) {
  if (!started_) {
    started_ = true;
    next_us_ = now_us + period_us_;
    return true;
  }
  if (now_us < next_us_) return false;
  next_us_ += period_us_;
  if (next_us_ <= now_us) next_us_ = now_us + period_us_;  // fell behind by a period or more
  return true;
}

}  // namespace tonus::vmc
