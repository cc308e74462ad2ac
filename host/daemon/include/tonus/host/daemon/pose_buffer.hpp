// The tracker jitter buffer. Reference poses (the humanoid's qpos, already
// retargeted or solved by IK on the tracker thread) arrive stamped with their
// host arrival time; the physics thread asks for the pose at its tick's time
// minus a small fixed delay and gets the two samples around it interpolated
// (root position and hinges linearly, the root's and ball joints' rotations by
// slerp). So network jitter and the gap between a 60-120 Hz tracker and the
// 1 kHz physics never show as steps.
//
// A stream that stops is held for hold_s, then eased to a neutral pose (where
// the avatar stood and faced, upright, arms by its sides) over ease_s; when it
// comes back, the live pose is blended in over recover_s. Fixed capacity, no
// allocation after construction.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::daemon {

using Qpos = std::array<double, sim::kMaxQpos>;

struct PoseSample {
  std::int64_t t_us = 0;  // host steady clock, arrival (or the source's own time mapped to it)
  Qpos qpos{};
  // A new take (a looping clip starting over): not interpolated from the
  // sample before, so the reference steps and the controller resyncs to it
  // instead of sweeping the body across the gap in one sample interval.
  bool cut = false;
};

struct PoseBufferConfig {
  double delay_s = 0.03;  // behind real time: two frames of a 60 Hz stream, plus jitter
  double hold_s = 0.25;
  double ease_s = 0.5;
  double recover_s = 0.2;
};
std::string validate(const PoseBufferConfig& c);

enum class PoseState : std::uint8_t { none, live, held, easing, neutral, recovering };
std::string_view to_string(PoseState s);

// Linear / slerp interpolation of two configurations of `model` (u in 0..1).
void interpolate_qpos(const sim::Model& model, const Qpos& a, const Qpos& b, double u, Qpos& out);

// Upright, arms by the sides, at `from`'s floor position and heading.
void neutral_qpos(const sim::Model& model, const Qpos& from, Qpos& out);

class PoseBuffer {
 public:
  static constexpr std::size_t kCapacity = 64;

  PoseBuffer(const sim::Model& model, const PoseBufferConfig& config);

  // Samples must come in time order; an older one is dropped and counted.
  // When full, the oldest is overwritten.
  void push(const PoseSample& s);

  // The pose at host time now_us (the delay is applied here).
  PoseState sample(std::int64_t now_us, Qpos& out);

  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] std::uint64_t dropped_out_of_order() const { return out_of_order_; }
  [[nodiscard]] std::uint64_t received() const { return received_; }
  [[nodiscard]] std::int64_t newest_us() const;

 private:
  [[nodiscard]] const PoseSample& at(std::size_t i) const { return ring_[(head_ + i) % kCapacity]; }
  PoseState live_pose(std::int64_t t_us, Qpos& out) const;

  const sim::Model* model_;
  PoseBufferConfig config_;
  std::array<PoseSample, kCapacity> ring_{};
  std::size_t head_ = 0;  // oldest
  std::size_t count_ = 0;
  std::uint64_t out_of_order_ = 0;
  std::uint64_t received_ = 0;
  Qpos last_out_{};
  Qpos from_{};     // what a recovery blends from
  Qpos neutral_{};  // the neutral at the last live pose
  PoseState last_state_ = PoseState::none;
  std::int64_t recover_start_us_ = 0;
};

}  // namespace tonus::daemon
