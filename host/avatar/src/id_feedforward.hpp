// Variant (b) of the feedforward: inverse dynamics (RNEA) of the reference,
// its velocities and accelerations from the fixed-lag Kalman smoother of
// host/derivatives, so no second simulation runs. The smoother answers for
// the sample `lag` ticks back, so the reference is followed that late.
//
// Each dof is smoothed as a scalar: hinge angles and root positions as they
// are; ball joints and the root's rotation as the running sum of their
// body-frame rotation increments, whose derivative is the body-frame angular
// velocity the model's qvel holds (and its derivative, qacc).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "tonus/host/avatar/reference.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"
#include "tonus/sim/data.hpp"

namespace tonus::avatar::detail {

class IdFeedforward {
 public:
  // Empty error when made; allocates everything here.
  static std::unique_ptr<IdFeedforward> create(const sim::Model& model, double cutoff_hz, int lag, std::string& error);

  // Takes this tick's (checked) reference; writes the delayed reference,
  // its smoothed velocity, and the joint torques that realise it (root dofs
  // zero). False while warming up: the output is then the oldest sample with
  // the gravity and velocity terms only.
  bool push(const sim::Model& model, const ReferencePose& ref, ReferencePose& delayed, std::span<double> tau);

  // Forgets the history (after a jump).
  void reset();

 private:
  IdFeedforward() = default;

  int lag_ = 0;
  std::vector<derivatives::FixedLag> smoothers_;            // one per dof, made once
  std::vector<std::array<double, sim::kMaxQpos>> history_;  // the last lag + 1 references (ring)
  std::size_t pushed_ = 0;
  std::array<double, sim::kMaxDofs> coordinate_{};  // the running coordinates
  std::array<double, sim::kMaxQpos> last_qpos_{};
  std::array<double, sim::kMaxDofs> qacc_{};
  std::unique_ptr<sim::Data> scratch_;
};

}  // namespace tonus::avatar::detail
