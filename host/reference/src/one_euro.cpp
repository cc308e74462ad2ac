#include "tonus/host/reference/one_euro.hpp"

#include <cmath>
#include <numbers>

#include "first_order.hpp"

namespace tonus::reference {
namespace {

// The share of the way a first-order low-pass at `cutoff_hz` moves in dt.
double alpha(double cutoff_hz, double dt_s) {
  return detail::first_order_share(dt_s, 1.0 / (2.0 * std::numbers::pi * cutoff_hz));
}

}  // namespace

TrackerPose one_euro(const TrackerPose& sample, double dt_s, const OneEuroParams& p, OneEuroState& s) {
  if (!s.started || !(dt_s > 0.0)) {
    s.started = true;
    s.pos = sample.pos_m;
    s.rot = sample.rot;
    s.velocity.setZero();
    s.angular_velocity.setZero();
    return sample;
  }
  const double ad = alpha(p.derivative_cutoff_hz, dt_s);
  s.velocity += ad * ((sample.pos_m - s.pos) / dt_s - s.velocity);
  s.pos += alpha(p.min_cutoff_hz + p.position_beta * s.velocity.norm(), dt_s) * (sample.pos_m - s.pos);

  sim::Quat q = sample.rot;
  if (q.dot(s.rot) < 0.0) q.coeffs() = -q.coeffs();
  const sim::Vec3 turn = sim::quat_log((q * s.rot.conjugate()).normalized());  // world frame
  s.angular_velocity += ad * (turn / dt_s - s.angular_velocity);
  const double ar = alpha(p.min_cutoff_hz + p.rotation_beta * s.angular_velocity.norm(), dt_s);
  s.rot = s.rot.slerp(ar, q).normalized();
  return {s.pos, s.rot, true};
}

}  // namespace tonus::reference
