// How often the daemon sends a VMC frame: a fixed rate the caller polls with
// due(now). 1 to 200 Hz: avatar engines render at 30 to 144 Hz, so more is
// wasted, and SlimeVR's VMC sender caps itself at one bundle per 3 ms with
// the comment "200hz to not crash VSF" (VSeeFace); 200 Hz is the tested
// ceiling.
#pragma once

#include <cstdint>
#include <string>

namespace tonus::vmc {

class RateLimiter {
 public:
  static constexpr double kMinHz = 1.0;
  static constexpr double kMaxHz = 200.0;
  static constexpr double kDefaultHz = 60.0;

  // Empty when `hz` is usable, else why not (for config checking).
  static std::string validate(double hz);

  // A rate outside [kMinHz, kMaxHz] is clamped into it; NaN gives kDefaultHz.
  explicit RateLimiter(double hz = kDefaultHz);

  // True at most once per period (steady clock, microseconds). The first
  // call is due. Ticks stay on the first call's grid while the caller keeps
  // up; after a stall of more than a period the grid restarts at `now_us`
  // (no burst to catch up).
  bool due(std::int64_t now_us);

  void reset() { started_ = false; }
  [[nodiscard]] double hz() const { return hz_; }
  [[nodiscard]] std::int64_t period_us() const { return period_us_; }

 private:
  double hz_ = kDefaultHz;
  std::int64_t period_us_ = 0;
  std::int64_t next_us_ = 0;
  bool started_ = false;
};

}  // namespace tonus::vmc
