// The performer's stiffness as the physics thread sees it: the newest band
// report's levels, held while the band is live. When no report has arrived
// for `stale_after_s`, the stiffness eases linearly from the held value to a
// safe default over `ease_s` (so within stale_after_s + ease_s of the last
// report it is the default); the next report takes over again at once (the
// avatar controller's rate limit smooths the step). The default before the
// first report is the safe default too. docs/daemon.md says why 0.3.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "tonus/host/avatar/stiffness.hpp"

namespace tonus::daemon {

using Levels = std::array<double, avatar::kGroupCount>;

struct StiffnessInputConfig {
  double stale_after_s = 0.1;
  double ease_s = 0.09;  // below 0.1 s, so the default is reached within the 100 ms with a tick to spare
  Levels safe_default{0.3, 0.3, 0.3, 0.3};
};

// Empty when usable, else what is wrong (names the key).
std::string validate(const StiffnessInputConfig& c);

class StiffnessInput {
 public:
  explicit StiffnessInput(const StiffnessInputConfig& c) : config_(c), held_(c.safe_default) {}

  // A report's levels (0..1 per group; values outside are clamped, non-finite
  // ones keep the previous value), arrived at `arrival_us` (host steady clock).
  void on_report(std::int64_t arrival_us, const Levels& levels);

  // The stiffness to apply at host time `now_us`.
  [[nodiscard]] Levels at(std::int64_t now_us) const;
  [[nodiscard]] bool live(std::int64_t now_us) const;  // a report within stale_after_s
  [[nodiscard]] bool ever_received() const { return received_; }
  [[nodiscard]] std::int64_t last_arrival_us() const { return last_us_; }

 private:
  StiffnessInputConfig config_;
  Levels held_;
  std::int64_t last_us_ = 0;
  bool received_ = false;
};

}  // namespace tonus::daemon
