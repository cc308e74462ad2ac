// Inverse-dynamics feedforward with fixed-lag derivatives.
#include "id_feedforward.hpp"

#include <algorithm>
#include <utility>

#include "tonus/sim/step.hpp"

namespace tonus::avatar::detail {

using std::size_t;

std::unique_ptr<IdFeedforward> IdFeedforward::create(const sim::Model& model, double cutoff_hz, int lag,
                                                     std::string& error) {
  if (lag < 1 || static_cast<size_t>(lag) > derivatives::FixedLag::kMaxLag) {
    error = "id_lag_ticks must be in 1.." + std::to_string(derivatives::FixedLag::kMaxLag);
    return nullptr;
  }
  reference::ReferenceVelocity::Created made =
      reference::ReferenceVelocity::create(model, model.timestep_s, cutoff_hz, lag);
  if (!made) {
    error = "id_cutoff_hz: the smoother refuses it for this time step";
    return nullptr;
  }
  std::unique_ptr<IdFeedforward> f(new IdFeedforward());
  f->velocity_ = std::move(made.velocity);
  f->scratch_ = sim::make_data(model);
  return f;
}

void IdFeedforward::reset() { velocity_->reset(); }

bool IdFeedforward::push(const sim::Model& model, const ReferencePose& ref, ReferencePose& delayed,
                         std::span<double> tau) {
  const auto nv = static_cast<size_t>(model.nv);
  const bool valid = velocity_->push(std::span<const double>(ref.qpos.data(), static_cast<size_t>(model.nq)), out_);
  delayed.qpos = out_.qpos;
  std::copy_n(out_.qvel.begin(), nv, delayed.qvel.begin());
  delayed.has_velocity = true;

  sim::Data& s = *scratch_;
  s.qpos = delayed.qpos;
  std::copy_n(delayed.qvel.begin(), nv, s.qvel.begin());
  sim::forward_kinematics(model, s);
  sim::inverse_dynamics(model, s, out_.qacc, tau);
  for (int k = 0; k < model.bodies[0].dof_num; ++k) tau[static_cast<size_t>(k)] = 0.0;  // the root is prescribed
  return valid;
}

}  // namespace tonus::avatar::detail
