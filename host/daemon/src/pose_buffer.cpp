#include "tonus/host/daemon/pose_buffer.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::daemon {
namespace {

sim::Quat quat_at(const Qpos& q, std::size_t a) { return {q[a], q[a + 1], q[a + 2], q[a + 3]}; }
void put_quat(Qpos& q, std::size_t a, const sim::Quat& r) {
  q[a] = r.w();
  q[a + 1] = r.x();
  q[a + 2] = r.y();
  q[a + 3] = r.z();
}

}  // namespace

std::string validate(const PoseBufferConfig& c) {
  const auto bad = [](double v, double hi) { return !std::isfinite(v) || v < 0.0 || v > hi; };
  if (bad(c.delay_s, 1.0)) return fmt::format("tracker.delay_ms = {}: must be 0..1000", c.delay_s * 1e3);
  if (bad(c.hold_s, 60.0)) return fmt::format("tracker.hold_ms = {}: must be 0..60000", c.hold_s * 1e3);
  if (bad(c.ease_s, 60.0)) return fmt::format("tracker.ease_ms = {}: must be 0..60000", c.ease_s * 1e3);
  if (bad(c.recover_s, 10.0)) return fmt::format("tracker.recover_ms = {}: must be 0..10000", c.recover_s * 1e3);
  return {};
}

std::string_view to_string(PoseState s) {
  switch (s) {
    case PoseState::none: return "none";
    case PoseState::live: return "live";
    case PoseState::held: return "held";
    case PoseState::easing: return "easing";
    case PoseState::neutral: return "neutral";
    case PoseState::recovering: return "recovering";
  }
  return "?";
}

void interpolate_qpos(const sim::Model& model, const Qpos& a, const Qpos& b, double u, Qpos& out) {
  u = std::clamp(u, 0.0, 1.0);
  for (int i = 0; i < model.nbody; ++i) {
    const sim::Body& body = model.bodies[static_cast<std::size_t>(i)];
    const auto adr = static_cast<std::size_t>(body.qpos_adr);
    switch (body.joint) {
      case sim::JointType::free:
        for (std::size_t k = 0; k < 3; ++k) out[adr + k] = a[adr + k] + u * (b[adr + k] - a[adr + k]);
        put_quat(out, adr + 3, quat_at(a, adr + 3).slerp(u, quat_at(b, adr + 3)).normalized());
        break;
      case sim::JointType::ball: put_quat(out, adr, quat_at(a, adr).slerp(u, quat_at(b, adr)).normalized()); break;
      case sim::JointType::hinge: out[adr] = a[adr] + u * (b[adr] - a[adr]); break;
      case sim::JointType::fixed: break;
    }
  }
}

void neutral_qpos(const sim::Model& model, const Qpos& from, Qpos& out) {
  out = model.qpos0;
  const sim::Body& root = model.bodies[0];
  if (root.joint == sim::JointType::free) {
    const auto adr = static_cast<std::size_t>(root.qpos_adr);
    out[adr] = from[adr];
    out[adr + 1] = from[adr + 1];
    // Heading only: the body's forward axis (+X) projected on the floor.
    const sim::Vec3 fwd = quat_at(from, adr + 3) * sim::Vec3::UnitX();
    const double yaw = std::hypot(fwd.x(), fwd.y()) > 1e-6 ? std::atan2(fwd.y(), fwd.x()) : 0.0;
    put_quat(out, adr + 3, sim::Quat(Eigen::AngleAxisd(yaw, sim::Vec3::UnitZ())));
  }
  // Arms 1.3 rad below the T-pose, by the sides (the left arm points +Y, the right -Y).
  const auto arm = [&](sim::Bone b, double angle) {
    const sim::Body& body = model.bodies[sim::index(b)];
    if (body.joint == sim::JointType::ball) {
      put_quat(out, static_cast<std::size_t>(body.qpos_adr), sim::Quat(Eigen::AngleAxisd(angle, sim::Vec3::UnitX())));
    }
  };
  if (static_cast<std::size_t>(model.nbody) == sim::kBoneCount) {
    arm(sim::Bone::LeftUpperArm, -1.3);
    arm(sim::Bone::RightUpperArm, 1.3);
  }
}

PoseBuffer::PoseBuffer(const sim::Model& model, const PoseBufferConfig& config)
    : model_(&model), config_(config), last_out_(model.qpos0), from_(model.qpos0) {
  neutral_qpos(model, model.qpos0, neutral_);
}

std::int64_t PoseBuffer::newest_us() const { return count_ > 0 ? at(count_ - 1).t_us : 0; }

void PoseBuffer::push(const PoseSample& s) {
  if (count_ > 0 && s.t_us <= newest_us()) {
    ++out_of_order_;
    return;
  }
  ++received_;
  if (count_ == kCapacity) {
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  ring_[(head_ + count_) % kCapacity] = s;
  ++count_;
}

PoseState PoseBuffer::live_pose(std::int64_t t_us, Qpos& out) const {
  if (t_us <= at(0).t_us) {
    out = at(0).qpos;
    return PoseState::live;
  }
  for (std::size_t i = 1; i < count_; ++i) {
    const PoseSample& b = at(i);
    if (t_us <= b.t_us) {
      const PoseSample& a = at(i - 1);
      if (b.cut) {  // a step: the old take until the new one starts
        out = t_us < b.t_us ? a.qpos : b.qpos;
        return PoseState::live;
      }
      const double u = static_cast<double>(t_us - a.t_us) / static_cast<double>(b.t_us - a.t_us);
      interpolate_qpos(*model_, a.qpos, b.qpos, u, out);
      return PoseState::live;
    }
  }
  out = at(count_ - 1).qpos;
  return PoseState::held;
}

PoseState PoseBuffer::sample(std::int64_t now_us, Qpos& out) {
  const std::int64_t t_us = now_us - static_cast<std::int64_t>(std::llround(config_.delay_s * 1e6));
  PoseState state = PoseState::none;
  if (count_ == 0) {
    out = neutral_;
  } else {
    state = live_pose(t_us, out);
    if (state == PoseState::held) {
      neutral_qpos(*model_, at(count_ - 1).qpos, neutral_);  // where the newest pose stood and faced
      const double silent_s = static_cast<double>(t_us - newest_us()) * 1e-6;
      if (silent_s > config_.hold_s + config_.ease_s) {
        out = neutral_;
        state = PoseState::neutral;
      } else if (silent_s > config_.hold_s) {
        const double u = config_.ease_s > 0.0 ? (silent_s - config_.hold_s) / config_.ease_s : 1.0;
        interpolate_qpos(*model_, at(count_ - 1).qpos, neutral_, u, out);
        state = PoseState::easing;
      }
    } else {
      // Back from easing or neutral: blend from what was shown over recover_s.
      const bool returning = last_state_ == PoseState::easing || last_state_ == PoseState::neutral;
      if (returning) {
        from_ = last_out_;
        recover_start_us_ = now_us;
      }
      if (returning || last_state_ == PoseState::recovering) {
        const double since_s = static_cast<double>(now_us - recover_start_us_) * 1e-6;
        const double u = config_.recover_s > 0.0 ? since_s / config_.recover_s : 1.0;
        if (u < 1.0) {
          interpolate_qpos(*model_, from_, out, u, out);
          state = PoseState::recovering;
        }
      }
    }
  }
  last_out_ = out;
  last_state_ = state;
  return state;
}

}  // namespace tonus::daemon
