// Velocities and accelerations of a stream of reference configurations (the
// humanoid's qpos, one per frame), from the fixed-lag Kalman smoother of
// host/derivatives: the output is the configuration `lag` frames back with its
// smoothed qvel and qacc, in the model's qvel layout (sim/model.hpp):
//   root   linear velocity of the origin (3, world) + angular velocity (3, root frame)
//   ball   angular velocity (3, body frame)
//   hinge  angle rate (1)
// ready for the avatar controller (its inverse-dynamics feedforward) or any
// consumer that wants the reference's derivatives.
//
// Each dof is smoothed as a scalar (derivatives::FixedLag, Method::kalman):
// hinge angles and the root's position as they are; ball joints and the root's
// rotation as the running sum of their body-frame rotation increments
// log(q_{k-1}^-1 q_k), whose derivative is the body-frame angular velocity the
// model's qvel holds. The increment takes the short way round, so a quaternion
// whose sign flips between frames (q and -q are one rotation) changes nothing;
// the output quaternions are put in the previous frame's hemisphere.
//
// Input checks, per joint: a position not finite or beyond 1e6 m, a hinge
// angle beyond 1e3 rad, a quaternion not finite or of norm outside 0.5..2 is a
// missing sample: its dofs are fed NaN, which the smoother bridges (as gaps in
// host/derivatives), and the next usable quaternion's increment is taken from
// the last usable one. The delayed configuration of a missing joint is filled
// from the smoother's estimate (positions, angles; rotations: the last usable
// quaternion turned by the smoothed coordinate's change), or held when there is
// none. A gap longer than the lag is extrapolated by the smoother (constant
// acceleration): reset after a long loss. Quaternions are normalised when their
// norm is off 1 by more than 1e-12 (a unit input passes bit for bit).
//
// A jump in the reference (a teleport, a new clip) is not a motion: call
// reset(), which forgets the history; the output is then the first sample
// after the reset, at zero velocity, until `lag` frames have passed.
//
// Model / data split: create() allocates everything (the smoothers, the ring of
// the last lag + 1 frames); push() allocates nothing, never throws and writes
// no non-finite value. One instance per stream; it keeps no reference to the
// model.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tonus/host/derivatives/fixed_lag.hpp"
#include "tonus/sim/capacity.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference {

struct ReferenceVelocityOutput {
  // The configuration `lag` frames before the last one pushed (while warming
  // up: the oldest since the reset), the model's qpos layout, nq entries.
  std::array<double, sim::kMaxQpos> qpos{};
  // Its smoothed velocity and acceleration, nv entries (the qvel layout); zero
  // for a dof whose smoother is not yet valid.
  std::array<double, sim::kMaxDofs> qvel{};
  std::array<double, sim::kMaxDofs> qacc{};
  // Every dof's estimate valid: `lag` frames pushed since the reset, and
  // 3 usable samples of every joint.
  bool warm = false;
  std::size_t index = 0;   // which sample since the reset (0 = the first) qpos is
  int missing_joints = 0;  // joints of that sample that were missing (filled or held); the root counts twice
};

class ReferenceVelocity {
 public:
  using Output = ReferenceVelocityOutput;
  struct Created;

  // dt_s: the frame interval; cutoff_hz: the smoother's -6 dB frequency
  // (derivatives::Params::cutoff_hz); lag_frames in 0..derivatives::FixedLag::kMaxLag
  // (0: the causal filter, no delay). Error when the smoother refuses them.
  static Created create(const sim::Model& model, double dt_s, double cutoff_hz, int lag_frames);

  // Takes the next frame's qpos (at least nq entries; fewer: every joint
  // missing) and writes the delayed frame. Returns out.warm.
  bool push(std::span<const double> qpos, Output& out) noexcept;

  // Forgets every frame (after a jump); keeps the parameters.
  void reset() noexcept;

  [[nodiscard]] int lag() const { return lag_; }
  [[nodiscard]] double dt_s() const { return dt_s_; }
  [[nodiscard]] double delay_s() const { return lag_ * dt_s_; }
  [[nodiscard]] std::size_t pushed() const { return pushed_; }  // since the reset

 private:
  ReferenceVelocity() = default;

  struct Joint {
    sim::JointType type = sim::JointType::fixed;
    std::size_t qpos_adr = 0;
    std::size_t dof_adr = 0;
  };
  // One frame of the ring: the configuration (a missing joint holds its last
  // usable value), the running coordinates (a missing joint's: at that value),
  // and which dofs were missing.
  struct Frame {
    std::array<double, sim::kMaxQpos> qpos{};
    std::array<double, sim::kMaxDofs> coordinate{};
    std::uint64_t missing = 0;  // bit d: dof d
    std::uint64_t seen = 0;     // bit d: dof d had a usable sample at or before this frame
  };

  void fill_missing(Frame& f, std::span<const derivatives::Estimate> e) const noexcept;

  int lag_ = 0;
  double dt_s_ = 0.0;
  int nq_ = 0;
  int nv_ = 0;
  int njoint_ = 0;
  std::array<Joint, sim::kMaxBodies> joints_{};
  std::array<double, sim::kMaxQpos> qpos0_{};
  std::vector<derivatives::FixedLag> smoothers_;  // one per dof
  std::vector<Frame> ring_;                       // the last lag + 1 frames: frame k at k % size
  std::size_t pushed_ = 0;
  Frame current_;  // the running state: last usable values and coordinates
  std::array<derivatives::Estimate, sim::kMaxDofs> estimates_{};
};

struct ReferenceVelocity::Created {
  std::optional<ReferenceVelocity> velocity;  // empty when error is set
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
  explicit operator bool() const { return ok(); }
};

}  // namespace tonus::reference
