// From the performer's stiffness (0..1 per group, from the band) to the weak
// drives of simulation B: a documented group table (which joints each group
// drives), a natural frequency interpolated on a log scale between a minimum
// and a maximum per group, Kp = w^2 I and Kd = 2 zeta w I per dof from the
// joint's effective inertia, and a rate limit so a jump in level never makes
// the avatar pop. docs/avatar.md gives the sources of the defaults.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/inputs.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::avatar {

// The band's four default groups (docs/protocol.md: right arm, left arm, trunk, legs).
inline constexpr std::size_t kGroupCount = 4;
enum class Group : std::uint8_t { right_arm = 0, left_arm = 1, trunk = 2, legs = 3 };
std::string_view to_string(Group g);

inline constexpr std::int8_t kNoGroup = -1;

struct GroupCurve {
  double min_hz = 2.0;         // natural frequency at stiffness 0 (relaxed)
  double max_hz = 6.0;         // ... at stiffness 1 (full co-contraction)
  double damping_ratio = 1.0;  // at every stiffness
};

struct StiffnessConfig {
  // Group of each bone's joint; kNoGroup: the joint follows `ungrouped`.
  std::array<std::int8_t, sim::kBoneCount> bone_group{};
  std::array<GroupCurve, kGroupCount> curves{};
  GroupCurve ungrouped{2.0, 2.0, 1.0};  // joints no group drives
  // Largest change of stiffness per second (0 -> 1 in 1 / rate seconds).
  double max_rate_per_s = 5.0;
  // Stiffness before the first valid value arrives.
  double initial = 0.5;
};

// The defaults: the band's four groups over the humanoid's bones (arms from
// the shoulder to the hand, trunk from the spine to the head, legs from the
// hip to the toes), 2..6 Hz critically damped (docs/avatar.md).
StiffnessConfig default_stiffness_config();

// Empty when usable, else what is wrong (names the field).
std::string validate(const StiffnessConfig& c);

// The effective inertia each dof's drive sees at the model's rest pose with a
// prescribed root: the diagonal of the joint-space inertia (plus armature).
std::array<double, sim::kMaxDofs> effective_inertia(const sim::Model& model);

// Per-tick state: the rate-limited stiffness per group and the gains it gives.
class StiffnessMapper {
 public:
  static constexpr int kUndriven = -2;  // dof_group() of the root's dofs
  StiffnessMapper(const sim::Model& model, const StiffnessConfig& config);

  struct Update {
    int clamped = 0;   // values outside 0..1 clamped
    int rejected = 0;  // non-finite values ignored (the last valid kept)
    bool rate_limited = false;
  };
  // Takes the requested stiffness per group, moves the applied stiffness
  // towards it by at most max_rate_per_s * dt_s, and writes B's gains.
  Update update(const std::array<double, kGroupCount>& requested, double dt_s);

  // The effective inertia per dof from now on: the diagonal of a joint-space
  // inertia (nv x nv, row stride nv, as sim::Data::mass), so the gains follow
  // the posture (an upper arm's twist carries the forearm when the elbow is
  // bent, hardly anything when it is straight). Non-finite or non-positive
  // entries keep the previous value.
  void set_inertia(std::span<const double> mass, int nv);

  // Writes the current gains into `in` (joint dofs; the root's are left alone).
  void write_gains(const sim::Model& model, sim::StepInputs& in) const;

  [[nodiscard]] const std::array<double, kGroupCount>& applied() const { return applied_; }
  [[nodiscard]] const std::array<double, kGroupCount>& target() const { return target_; }
  // Natural frequency of a group at a stiffness, Hz (the log-scale curve).
  [[nodiscard]] double frequency_hz(std::size_t group, double stiffness) const;
  [[nodiscard]] int dof_group(std::size_t dof) const { return dof_group_[dof]; }
  [[nodiscard]] double kp(std::size_t dof) const { return kp_[dof]; }
  [[nodiscard]] double kd(std::size_t dof) const { return kd_[dof]; }
  [[nodiscard]] double inertia(std::size_t dof) const { return inertia_[dof]; }
  // Jumps straight to these values (no rate limit): for experiments and resets.
  void set_applied(const std::array<double, kGroupCount>& s);

 private:
  void recompute();

  StiffnessConfig config_;
  int nv_ = 0;
  std::array<double, sim::kMaxDofs> inertia_{};
  std::array<int, sim::kMaxDofs> dof_group_{};  // group, kNoGroup, or kUndriven
  std::array<double, kGroupCount> target_{};
  std::array<double, kGroupCount> applied_{};
  std::array<double, sim::kMaxDofs> kp_{};
  std::array<double, sim::kMaxDofs> kd_{};
};

// Gains of the stiff drives (simulation A): a natural frequency per group
// (ungrouped joints take `ungrouped_hz`), critically damped at
// `damping_ratio`, with the same effective inertia per dof as B's.
void write_stiff_gains(const sim::Model& model, const StiffnessMapper& mapper,
                       const std::array<double, kGroupCount>& group_hz, double ungrouped_hz, double damping_ratio,
                       sim::StepInputs& in);

}  // namespace tonus::avatar
