// Variant (b) of the feedforward: inverse dynamics (RNEA) of the reference,
// its velocities and accelerations from the fixed-lag Kalman smoother
// (reference::ReferenceVelocity, host/reference), so no second simulation
// runs. The smoother answers for the sample `lag` ticks back, so the reference
// is followed that late.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>

#include "tonus/host/avatar/reference.hpp"
#include "tonus/host/reference/reference_velocity.hpp"
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

  std::optional<reference::ReferenceVelocity> velocity_;  // made once
  reference::ReferenceVelocity::Output out_;
  std::unique_ptr<sim::Data> scratch_;
};

}  // namespace tonus::avatar::detail
