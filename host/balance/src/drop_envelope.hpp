// The pelvis's drop as a smooth function of time. Frame by frame, the drop a
// straight stance leg needs to keep its foot (waist_turn) comes and goes
// within a frame or two: a vertical jolt of the whole upper body, visible on
// the avatar (up to 8 mm between two frames at 30 Hz) and, through its
// vertical acceleration (up to 12 m/s^2 on the shared clips), a swing of the
// ZMP by metres under a 12 Hz estimate. The envelope is at least every
// frame's need and eases in and out over about `kDropEase_s` either side:
// each need spread by a raised cosine, the upper envelope of those smoothed by
// a Gaussian, the cosines raised by the share the smoothing takes off a peak
// so the result never falls below a need (the smoothing is linear and
// monotone: at a need's own frame it gives at least that need).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace tonus::balance::detail {

// Half the width of a need's raised cosine, and the Gaussian's deviation:
// together 0.25 s, the online filter's look-ahead, so a live stream can ease
// in before the need. An 8 mm need alone then accelerates the pelvis by
// about 1 m/s^2 at 30 Hz, against the 6-12 m/s^2 of the frame-wise drop.
inline constexpr double kDropEase_s = 0.15;
inline constexpr double kDropSmoothing_s = 0.0333;

class DropEnvelope {
 public:
  static constexpr std::size_t kMaxReach = 64;  // frames either side (0.25 s at up to 250 Hz)
  // `max_reach_frames` bounds how far ahead a frame's drop may look (the
  // online filter's look-ahead); the ease is shortened to fit.
  DropEnvelope(double dt_s, std::size_t max_reach_frames = kMaxReach);
  // Frames either side a frame's smoothed drop depends on.
  [[nodiscard]] std::size_t reach() const { return ease_ + blur_; }
  // The smoothed drop at frame t of `need` (metres, > 0 down; frames outside
  // [0, count) need none). Reads need[t - reach() .. t + reach()].
  [[nodiscard]] double at(const double* need, std::size_t count, std::size_t t) const;
  // A whole sequence (the offline filter's).
  [[nodiscard]] std::vector<double> smooth(const std::vector<double>& need) const;

 private:
  // The upper envelope at frame j of the needs spread by the raised cosine.
  [[nodiscard]] double spread(const double* need, std::ptrdiff_t count, std::ptrdiff_t j) const;

  std::size_t ease_ = 0;  // the raised cosine's half width, frames
  std::size_t blur_ = 0;  // the Gaussian's half width (3 deviations), frames
  std::array<double, kMaxReach + 1> cosine_{};
  std::array<double, kMaxReach + 1> gauss_{};
  double raise_ = 1.0;  // 1 / (the Gaussian's average of the cosine at its peak)
};

}  // namespace tonus::balance::detail
