// Fixed-lag velocities and accelerations of a reference stream.
#include "tonus/host/reference/reference_velocity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "tonus/sim/math.hpp"

namespace tonus::reference {

using std::size_t;

namespace {

constexpr double kMaxPositionM = 1e6;
constexpr double kMaxAngleRad = 1e3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr std::uint64_t bits(size_t first, size_t count) { return ((std::uint64_t{1} << count) - 1U) << first; }

// The quaternion at q[a..a+3] if usable (finite, norm in 0.5..2), normalised
// unless already unit to 1e-12.
bool usable_quat(std::span<const double> q, size_t a, sim::Quat& out) {
  const sim::Quat r(q[a], q[a + 1], q[a + 2], q[a + 3]);
  const double n = r.norm();
  if (!std::isfinite(n) || !(n > 0.5 && n < 2.0)) return false;
  out = std::abs(n - 1.0) > 1e-12 ? sim::Quat(r.coeffs() / n) : r;
  return true;
}

sim::Quat quat_at(const std::array<double, sim::kMaxQpos>& q, size_t a) { return {q[a], q[a + 1], q[a + 2], q[a + 3]}; }

void put_quat(std::array<double, sim::kMaxQpos>& q, size_t a, const sim::Quat& r) {
  q[a] = r.w();
  q[a + 1] = r.x();
  q[a + 2] = r.y();
  q[a + 3] = r.z();
}

double finite_or(double x, double fallback) { return std::isfinite(x) ? x : fallback; }

}  // namespace

ReferenceVelocity::Created ReferenceVelocity::create(const sim::Model& model, double dt_s, double cutoff_hz,
                                                     int lag_frames) {
  Created c;
  if (lag_frames < 0 || static_cast<size_t>(lag_frames) > derivatives::FixedLag::kMaxLag) {
    c.error = "reference velocity: lag_frames must be in 0.." + std::to_string(derivatives::FixedLag::kMaxLag);
    return c;
  }
  if (model.nbody < 1 || model.nq < 0 || model.nv < 0 || static_cast<size_t>(model.nq) > sim::kMaxQpos ||
      static_cast<size_t>(model.nv) > sim::kMaxDofs || static_cast<size_t>(model.nbody) > sim::kMaxBodies) {
    c.error = "reference velocity: the model is empty or beyond sim's capacity";
    return c;
  }
  derivatives::Params p;
  p.method = derivatives::Method::kalman;
  p.cutoff_hz = cutoff_hz;
  derivatives::FixedLag::Created made = derivatives::FixedLag::create(dt_s, p, static_cast<size_t>(lag_frames));
  if (!made) {
    c.error = "reference velocity: the smoother refuses dt_s = " + std::to_string(dt_s) +
              " s with cutoff_hz = " + std::to_string(cutoff_hz);
    return c;
  }
  ReferenceVelocity v;
  v.lag_ = lag_frames;
  v.dt_s_ = dt_s;
  v.nq_ = model.nq;
  v.nv_ = model.nv;
  v.njoint_ = model.nbody;
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& b = model.bodies[static_cast<size_t>(i)];
    v.joints_[static_cast<size_t>(i)] = {b.joint, static_cast<size_t>(b.qpos_adr), static_cast<size_t>(b.dof_adr)};
  }
  v.qpos0_ = model.qpos0;
  v.smoothers_.assign(static_cast<size_t>(model.nv), *made.smoother);
  v.ring_.assign(static_cast<size_t>(lag_frames) + 1, Frame{});
  v.reset();
  c.velocity = std::move(v);
  return c;
}

void ReferenceVelocity::reset() noexcept {
  for (derivatives::FixedLag& s : smoothers_) s.reset();
  pushed_ = 0;
  current_ = Frame{};
  current_.qpos = qpos0_;
}

bool ReferenceVelocity::push(std::span<const double> qpos, Output& out) noexcept {
  Frame& cur = current_;
  cur.missing = 0;
  const bool sized = qpos.size() >= static_cast<size_t>(nq_);

  // A rotation's running coordinate: the body-frame increment from the last usable quaternion.
  auto rotation = [&](size_t a, size_t d) {
    sim::Quat q;
    if (!sized || !usable_quat(qpos, a, q)) {
      cur.missing |= bits(d, 3);
      return;
    }
    if ((cur.seen & bits(d, 3)) != 0) {
      const sim::Quat last = quat_at(cur.qpos, a);
      const sim::Vec3 inc = sim::quat_between(last, q);  // the short way: q and -q give the same
      for (size_t k = 0; k < 3; ++k) cur.coordinate[d + k] += inc(static_cast<Eigen::Index>(k));
      if (last.coeffs().dot(q.coeffs()) < 0.0) q.coeffs() = -q.coeffs();
    }
    put_quat(cur.qpos, a, q);
    cur.seen |= bits(d, 3);
  };
  auto scalar = [&](size_t a, size_t d, double limit) {
    const double x = sized ? qpos[a] : kNaN;
    if (!(std::abs(x) <= limit)) {  // false for NaN too
      cur.missing |= bits(d, 1);
      return;
    }
    cur.qpos[a] = x;
    cur.coordinate[d] = x;
    cur.seen |= bits(d, 1);
  };

  for (size_t i = 0; i < static_cast<size_t>(njoint_); ++i) {
    const Joint& j = joints_[i];
    switch (j.type) {
      case sim::JointType::free: {
        bool ok = sized;
        for (size_t k = 0; k < 3 && ok; ++k) ok = std::abs(qpos[j.qpos_adr + k]) <= kMaxPositionM;
        if (ok) {
          for (size_t k = 0; k < 3; ++k) scalar(j.qpos_adr + k, j.dof_adr + k, kMaxPositionM);
        } else {
          cur.missing |= bits(j.dof_adr, 3);  // the position goes as a whole
        }
        rotation(j.qpos_adr + 3, j.dof_adr + 3);
        break;
      }
      case sim::JointType::ball: rotation(j.qpos_adr, j.dof_adr); break;
      case sim::JointType::hinge: scalar(j.qpos_adr, j.dof_adr, kMaxAngleRad); break;
      case sim::JointType::fixed: break;
    }
  }

  const auto nv = static_cast<size_t>(nv_);
  for (size_t d = 0; d < nv; ++d) {
    const double x = (cur.missing & bits(d, 1)) != 0 ? kNaN : cur.coordinate[d];
    estimates_[d] = smoothers_[d].push(x);
  }
  ring_[pushed_ % ring_.size()] = cur;
  ++pushed_;

  // The delayed frame: `lag` back, or the oldest while warming up.
  const size_t back = std::min(pushed_ - 1, static_cast<size_t>(lag_));
  Frame f = ring_[(pushed_ - 1 - back) % ring_.size()];
  bool warm = true;
  for (size_t d = 0; d < nv; ++d) {
    const derivatives::Estimate& e = estimates_[d];
    warm = warm && e.valid;
    out.qvel[d] = e.valid ? finite_or(e.vel, 0.0) : 0.0;
    out.qacc[d] = e.valid ? finite_or(e.acc, 0.0) : 0.0;
  }
  if (f.missing != 0) fill_missing(f, estimates_);
  out.qpos = f.qpos;
  out.warm = warm;
  out.index = pushed_ - 1 - back;
  int missing = 0;
  for (size_t i = 0; i < static_cast<size_t>(njoint_); ++i) {
    const Joint& j = joints_[i];
    switch (j.type) {
      case sim::JointType::free:
        missing += (f.missing & bits(j.dof_adr, 3)) != 0 ? 1 : 0;
        missing += (f.missing & bits(j.dof_adr + 3, 3)) != 0 ? 1 : 0;
        break;
      case sim::JointType::ball: missing += (f.missing & bits(j.dof_adr, 3)) != 0 ? 1 : 0; break;
      case sim::JointType::hinge: missing += (f.missing & bits(j.dof_adr, 1)) != 0 ? 1 : 0; break;
      case sim::JointType::fixed: break;
    }
  }
  out.missing_joints = missing;
  return warm;
}

// A missing joint of the delayed frame from the smoother's estimate for it
// (valid only once warm, when the estimate is for this very frame); else held.
void ReferenceVelocity::fill_missing(Frame& f, std::span<const derivatives::Estimate> e) const noexcept {
  auto rotation = [&](size_t a, size_t d) {
    if ((f.missing & bits(d, 3)) == 0 || (f.seen & bits(d, 3)) == 0) return;  // present, or rest
    sim::Vec3 turn;
    for (size_t k = 0; k < 3; ++k) {
      if (!e[d + k].valid) return;
      turn(static_cast<Eigen::Index>(k)) = e[d + k].pos - f.coordinate[d + k];
    }
    if (!sim::all_finite(turn)) return;
    const sim::Quat held = quat_at(f.qpos, a);
    put_quat(f.qpos, a, (held * sim::quat_exp(turn)).normalized());
  };
  auto scalar = [&](size_t a, size_t d, double limit) {
    if ((f.missing & bits(d, 1)) == 0 || !e[d].valid || !(std::abs(e[d].pos) <= limit)) return;
    f.qpos[a] = e[d].pos;
  };
  for (size_t i = 0; i < static_cast<size_t>(njoint_); ++i) {
    const Joint& j = joints_[i];
    switch (j.type) {
      case sim::JointType::free:
        for (size_t k = 0; k < 3; ++k) scalar(j.qpos_adr + k, j.dof_adr + k, kMaxPositionM);
        rotation(j.qpos_adr + 3, j.dof_adr + 3);
        break;
      case sim::JointType::ball: rotation(j.qpos_adr, j.dof_adr); break;
      case sim::JointType::hinge: scalar(j.qpos_adr, j.dof_adr, kMaxAngleRad); break;
      case sim::JointType::fixed: break;
    }
  }
}

}  // namespace tonus::reference
