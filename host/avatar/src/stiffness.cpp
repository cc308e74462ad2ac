// Stiffness -> gains: the group table, the log-frequency curve, the rate limit.
#include "tonus/host/avatar/stiffness.hpp"

#include <algorithm>
#include <cmath>

#include "tonus/sim/data.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::avatar {

using sim::Bone;
using std::size_t;

std::string_view to_string(Group g) {
  switch (g) {
    case Group::right_arm: return "right_arm";
    case Group::left_arm: return "left_arm";
    case Group::trunk: return "trunk";
    case Group::legs: return "legs";
  }
  return "?";
}

StiffnessConfig default_stiffness_config() {
  StiffnessConfig c;
  c.bone_group.fill(kNoGroup);
  const auto put = [&](Group g, std::initializer_list<Bone> bones) {
    for (const Bone b : bones) c.bone_group[sim::index(b)] = static_cast<std::int8_t>(g);
  };
  put(Group::right_arm, {Bone::RightShoulder, Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand});
  put(Group::left_arm, {Bone::LeftShoulder, Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand});
  put(Group::trunk, {Bone::Spine, Bone::Chest, Bone::Neck, Bone::Head});
  put(Group::legs, {Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot, Bone::LeftToes, Bone::RightUpperLeg,
                    Bone::RightLowerLeg, Bone::RightFoot, Bone::RightToes});
  // Human joint stiffness spans roughly 1:9 from relaxed to full co-contraction
  // (elbow ~10 -> 90 N m/rad, Gomi & Osu 1998; Milner 2002), i.e. natural
  // frequencies 1:3 for the same inertia: 2 -> 6 Hz on the forearm's ~0.06 kg m^2.
  c.curves.fill(GroupCurve{1.5, 8.0, 1.0});
  // The trunk carries inverted pendulums (the head on the neck, the upper body
  // on the spine): below about sqrt(g / l) / (2 pi) ~ 1.6 Hz (l ~ 0.1 m, the
  // head's centre above the neck joint) gravity out-pulls the drive and the
  // head falls to its limit after a knock. 2.5 Hz keeps it up with margin.
  c.curves[static_cast<size_t>(Group::trunk)] = GroupCurve{2.5, 8.0, 1.0};
  c.curves[static_cast<size_t>(Group::right_arm)] = GroupCurve{1.5, 12.0, 1.0};
  c.curves[static_cast<size_t>(Group::left_arm)] = GroupCurve{1.5, 12.0, 1.0};
  return c;
}

std::string validate(const StiffnessConfig& c) {
  const auto curve_ok = [](const GroupCurve& g) {
    return std::isfinite(g.min_hz) && std::isfinite(g.max_hz) && g.min_hz > 0.0 && g.max_hz >= g.min_hz &&
           g.max_hz <= 200.0 && std::isfinite(g.damping_ratio) && g.damping_ratio >= 0.0 && g.damping_ratio <= 10.0;
  };
  for (size_t g = 0; g < kGroupCount; ++g) {
    if (!curve_ok(c.curves[g]))
      return "stiffness.curves." + std::string(to_string(static_cast<Group>(g))) +
             ": need 0 < min_hz <= max_hz <= 200 and damping_ratio in [0, 10]";
  }
  if (!curve_ok(c.ungrouped)) return "stiffness.ungrouped: need 0 < min_hz <= max_hz <= 200, damping_ratio in [0, 10]";
  for (size_t b = 0; b < sim::kBoneCount; ++b) {
    if (c.bone_group[b] < kNoGroup || c.bone_group[b] >= static_cast<std::int8_t>(kGroupCount))
      return "stiffness.bone_group." + std::string(sim::kBones[b].name) + ": not a group";
  }
  if (!std::isfinite(c.max_rate_per_s) || c.max_rate_per_s <= 0.0)
    return "stiffness.max_rate_per_s: must be finite and > 0";
  if (!std::isfinite(c.initial) || c.initial < 0.0 || c.initial > 1.0) return "stiffness.initial: must be in 0..1";
  return {};
}

std::array<double, sim::kMaxDofs> effective_inertia(const sim::Model& model) {
  auto data = sim::make_data(model);
  sim::forward_kinematics(model, *data);
  sim::mass_matrix(model, *data);
  std::array<double, sim::kMaxDofs> inertia{};
  const auto nv = static_cast<size_t>(model.nv);
  for (size_t d = 0; d < nv; ++d) inertia[d] = data->mass[d * nv + d];  // CRBA's diagonal holds the armature
  return inertia;
}

StiffnessMapper::StiffnessMapper(const sim::Model& model, const StiffnessConfig& config)
    : config_(config), nv_(model.nv), inertia_(effective_inertia(model)) {
  dof_group_.fill(kUndriven);
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    if (b.joint != sim::JointType::ball && b.joint != sim::JointType::hinge) continue;
    const int g = i < static_cast<int>(sim::kBoneCount) ? static_cast<int>(config_.bone_group[static_cast<size_t>(i)])
                                                        : static_cast<int>(kNoGroup);
    for (int k = b.dof_adr; k < b.dof_adr + b.dof_num; ++k) dof_group_[static_cast<size_t>(k)] = g;
  }
  target_.fill(config_.initial);
  applied_.fill(config_.initial);
  recompute();
}

double StiffnessMapper::frequency_hz(size_t group, double s) const {
  const GroupCurve& c = group < kGroupCount ? config_.curves[group] : config_.ungrouped;
  return c.min_hz * std::pow(c.max_hz / c.min_hz, std::clamp(s, 0.0, 1.0));
}

void StiffnessMapper::recompute() {
  // One curve evaluation per group (the last entry: ungrouped joints), then per dof.
  std::array<double, kGroupCount + 1> w{};
  std::array<double, kGroupCount + 1> zeta{};
  for (size_t g = 0; g <= kGroupCount; ++g) {
    w[g] = 2.0 * M_PI * frequency_hz(g, g < kGroupCount ? applied_[g] : 0.0);
    zeta[g] = (g < kGroupCount ? config_.curves[g] : config_.ungrouped).damping_ratio;
  }
  for (size_t d = 0; d < static_cast<size_t>(nv_); ++d) {
    const int g = dof_group_[d];
    if (g == kUndriven) {
      kp_[d] = kd_[d] = 0.0;
      continue;
    }
    const auto gu = g >= 0 ? static_cast<size_t>(g) : kGroupCount;
    kp_[d] = w[gu] * w[gu] * inertia_[d];
    kd_[d] = 2.0 * zeta[gu] * w[gu] * inertia_[d];
  }
}

StiffnessMapper::Update StiffnessMapper::update(const std::array<double, kGroupCount>& requested, double dt_s) {
  Update u;
  const double step = config_.max_rate_per_s * dt_s;
  for (size_t g = 0; g < kGroupCount; ++g) {
    double s = requested[g];
    if (!std::isfinite(s)) {
      ++u.rejected;
      s = target_[g];
    } else if (s < 0.0 || s > 1.0) {
      ++u.clamped;
      s = std::clamp(s, 0.0, 1.0);
    }
    target_[g] = s;
    const double moved = std::clamp(s - applied_[g], -step, step);
    if (moved != s - applied_[g]) u.rate_limited = true;
    applied_[g] += moved;
  }
  recompute();
  return u;
}

void StiffnessMapper::set_inertia(std::span<const double> mass, int nv) {
  if (nv != nv_) return;
  const auto n = static_cast<size_t>(nv);
  for (size_t d = 0; d < n; ++d) {
    const double i = mass[d * n + d];
    if (std::isfinite(i) && i > 0.0) inertia_[d] = i;
  }
  recompute();  // cheap: one curve evaluation per group
}

void StiffnessMapper::set_applied(const std::array<double, kGroupCount>& s) {
  for (size_t g = 0; g < kGroupCount; ++g) {
    if (std::isfinite(s[g])) target_[g] = applied_[g] = std::clamp(s[g], 0.0, 1.0);
  }
  recompute();
}

void StiffnessMapper::write_gains(const sim::Model& model, sim::StepInputs& in) const {
  for (size_t d = 0; d < static_cast<size_t>(model.nv); ++d) {
    in.kp[d] = kp_[d];
    in.kd[d] = kd_[d];
  }
}

void write_stiff_gains(const sim::Model& model, const StiffnessMapper& mapper,
                       const std::array<double, kGroupCount>& group_hz, double ungrouped_hz, double damping_ratio,
                       sim::StepInputs& in) {
  for (size_t d = 0; d < static_cast<size_t>(model.nv); ++d) {
    const int g = mapper.dof_group(d);
    if (g == StiffnessMapper::kUndriven) {
      in.kp[d] = in.kd[d] = 0.0;
      continue;
    }
    const double w = 2.0 * M_PI * (g >= 0 ? group_hz[static_cast<size_t>(g)] : ungrouped_hz);
    in.kp[d] = w * w * mapper.inertia(d);
    in.kd[d] = 2.0 * damping_ratio * w * mapper.inertia(d);
  }
}

}  // namespace tonus::avatar
