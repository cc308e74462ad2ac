#include "tonus/host/daemon/stiffness_input.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace tonus::daemon {

std::string validate(const StiffnessInputConfig& c) {
  if (!std::isfinite(c.stale_after_s) || c.stale_after_s < 0.005 || c.stale_after_s > 10.0) {
    return fmt::format("band.stale_after_ms = {}: must be 5..10000", c.stale_after_s * 1e3);
  }
  if (!std::isfinite(c.ease_s) || c.ease_s < 0.0 || c.ease_s > 10.0) {
    return fmt::format("band.ease_ms = {}: must be 0..10000", c.ease_s * 1e3);
  }
  for (const double v : c.safe_default) {
    if (!std::isfinite(v) || v < 0.0 || v > 1.0) return fmt::format("band.safe_stiffness = {}: must be 0..1", v);
  }
  return {};
}

void StiffnessInput::on_report(std::int64_t arrival_us, const Levels& levels) {
  for (std::size_t g = 0; g < levels.size(); ++g) {
    if (std::isfinite(levels[g])) held_[g] = std::clamp(levels[g], 0.0, 1.0);
  }
  last_us_ = std::max(last_us_, arrival_us);
  received_ = true;
}

bool StiffnessInput::live(std::int64_t now_us) const {
  return received_ && static_cast<double>(now_us - last_us_) * 1e-6 <= config_.stale_after_s;
}

Levels StiffnessInput::at(std::int64_t now_us) const {
  if (!received_) return config_.safe_default;
  const double silent_s = static_cast<double>(now_us - last_us_) * 1e-6;
  if (silent_s <= config_.stale_after_s) return held_;
  const double u = config_.ease_s > 0.0 ? (silent_s - config_.stale_after_s) / config_.ease_s : 1.0;
  if (u >= 1.0) return config_.safe_default;
  Levels out{};
  for (std::size_t g = 0; g < out.size(); ++g) out[g] = held_[g] + u * (config_.safe_default[g] - held_[g]);
  return out;
}

}  // namespace tonus::daemon
