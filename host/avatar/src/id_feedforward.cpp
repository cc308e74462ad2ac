// Inverse-dynamics feedforward with fixed-lag derivatives.
#include "id_feedforward.hpp"

#include <algorithm>
#include <cmath>

#include "reference_ops.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::avatar::detail {

using std::size_t;

std::unique_ptr<IdFeedforward> IdFeedforward::create(const sim::Model& model, double cutoff_hz, int lag,
                                                     std::string& error) {
  if (lag < 1 || static_cast<size_t>(lag) > derivatives::FixedLag::kMaxLag) {
    error = "id_lag_ticks must be in 1.." + std::to_string(derivatives::FixedLag::kMaxLag);
    return nullptr;
  }
  derivatives::Params p;
  p.method = derivatives::Method::kalman;
  p.cutoff_hz = cutoff_hz;
  auto made = derivatives::FixedLag::create(model.timestep_s, p, static_cast<size_t>(lag));
  if (!made) {
    error = "id_cutoff_hz: the smoother refuses it for this time step";
    return nullptr;
  }
  std::unique_ptr<IdFeedforward> f(new IdFeedforward());
  f->lag_ = lag;
  f->smoothers_.assign(static_cast<size_t>(model.nv), *made.smoother);
  f->history_.assign(static_cast<size_t>(lag) + 1, model.qpos0);
  f->scratch_ = sim::make_data(model);
  return f;
}

void IdFeedforward::reset() {
  for (auto& s : smoothers_) s.reset();
  pushed_ = 0;
  coordinate_.fill(0.0);
}

bool IdFeedforward::push(const sim::Model& model, const ReferencePose& ref, ReferencePose& delayed,
                         std::span<double> tau) {
  const auto nv = static_cast<size_t>(model.nv);
  // The running coordinates: positions as they are, rotations as summed increments.
  std::array<double, sim::kMaxDofs> increment{};
  if (pushed_ > 0) difference(model, last_qpos_, ref.qpos, 1.0, increment);
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    const auto a = static_cast<size_t>(b.qpos_adr);
    const auto d = static_cast<size_t>(b.dof_adr);
    switch (b.joint) {
      case sim::JointType::free:
        for (size_t k = 0; k < 3; ++k) coordinate_[d + k] = ref.qpos[a + k];
        for (size_t k = 3; k < 6; ++k) coordinate_[d + k] += increment[d + k];
        break;
      case sim::JointType::ball:
        for (size_t k = 0; k < 3; ++k) coordinate_[d + k] += increment[d + k];
        break;
      case sim::JointType::hinge: coordinate_[d] = ref.qpos[a]; break;
      case sim::JointType::fixed: break;
    }
  }
  last_qpos_ = ref.qpos;
  history_[pushed_ % history_.size()] = ref.qpos;
  ++pushed_;

  bool valid = true;
  for (size_t d = 0; d < nv; ++d) {
    const derivatives::Estimate e = smoothers_[d].push(coordinate_[d]);
    valid = valid && e.valid;
    delayed.qvel[d] = e.valid ? e.vel : 0.0;
    qacc_[d] = e.valid ? e.acc : 0.0;
  }
  const size_t back = std::min(pushed_ - 1, static_cast<size_t>(lag_));
  delayed.qpos = history_[(pushed_ - 1 - back) % history_.size()];
  delayed.has_velocity = true;

  sim::Data& s = *scratch_;
  s.qpos = delayed.qpos;
  std::copy_n(delayed.qvel.begin(), nv, s.qvel.begin());
  sim::forward_kinematics(model, s);
  sim::inverse_dynamics(model, s, qacc_, tau);
  for (int k = 0; k < model.bodies[0].dof_num; ++k) tau[static_cast<size_t>(k)] = 0.0;  // the root is prescribed
  return valid;
}

}  // namespace tonus::avatar::detail
