#include "foot_steps.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "body_frames.hpp"
#include "first_order.hpp"
#include "smoothstep.hpp"

namespace tonus::reference::detail {
namespace {

double wrap(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

// A planted foot's heading as seen from the pelvis: the pelvis's turn from
// the foot (`turn`, unwrapped) as it is up to `start`, then saturating
// smoothly (an exponential, matched in value and slope) toward start + width.
// A body that turns further pivots the foot about its ankle rather than
// twisting the leg into the ankle's and hip's ranges (a spinning kick's
// clamps dragged the standing foot round by fits).
double pivot_kept(double turn, double start, double width) {
  const double a = std::abs(turn);
  if (width <= 0.0 || a <= start) return turn;
  return std::copysign(start + width * (1.0 - std::exp(-(a - start) / width)), turn);
}

// A pelvis slowing under these shares of the speed its step started with is
// stopping: the landing point goes to its prediction at once (smoothstep
// between the two), so a stopped body stands on feet under its hips. The
// start speed counts as at least kStopSpeedFloor_mps (standing steps).
constexpr double kStopShareStart = 0.4;
constexpr double kStopShareFull = 0.1;
constexpr double kStopSpeedFloor_mps = 0.3;

// Progress under a constant push then a constant brake: zero speed at both
// ends and the least total change of acceleration (the integral of |jerk|)
// a rest-to-rest move can have, with a lower peak acceleration than
// minimum jerk's (4 against 5.8), which has 1.4 times its integral of |jerk|:
// what the jitter measures (docs/reference.md).
double swing_progress(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t < 0.5 ? 2.0 * t * t : 1.0 - 2.0 * (1.0 - t) * (1.0 - t);
}

sim::Vec3 ideal_ankle(const IkModel& m, const sim::Vec3& pelvis, double yaw, std::size_t side) {
  const sim::Vec3 local = horizontal(m.ankle_in_hips[side]);
  sim::Vec3 p = horizontal(pelvis) + yaw_quat(yaw) * local;
  p.z() = m.ankle_height_m;
  return p;
}

}  // namespace

void plant_feet(const IkModel& model, IkState& state, const sim::Vec3& pelvis, double pelvis_yaw_rad) {
  for (std::size_t s = 0; s < 2; ++s) {
    IkState::Foot& f = state.foot[s];
    f.planted = ideal_ankle(model, pelvis, pelvis_yaw_rad, s);
    f.yaw_rad = pelvis_yaw_rad;
    f.turn_rad = 0.0;
    f.phase = -1.0;
  }
}

bool advance_feet(const IkModel& model, IkState& state, const sim::Vec3& pelvis, double pelvis_yaw_rad, double dt_s,
                  const std::array<bool, 2>& tracked, std::array<FootTarget, 2>& out) {
  const IkOptions& o = model.options;
  const sim::Vec3 v = horizontal(state.pelvis_velocity);
  const double speed = v.norm();
  // A foot lands ahead of its place under the hip by step_lead_s of the
  // pelvis's travel, and lifts when it has fallen as far behind. Standing, a
  // small threshold keeps the stance tidy.
  std::array<sim::Vec3, 2> under{};
  for (std::size_t s = 0; s < 2; ++s) under[s] = ideal_ankle(model, pelvis, pelvis_yaw_rad, s);
  const double reach_out = std::max(o.step_threshold_m, o.step_lead_s * speed);

  const double pivot_start = o.foot_pivot_start_rad, pivot_width = o.foot_pivot_width_rad;
  // The pelvis's turn from each planted foot, followed unwrapped.
  for (IkState::Foot& f : state.foot) {
    if (f.phase < 0.0) f.turn_rad += wrap(pelvis_yaw_rad - f.yaw_rad - f.turn_rad);
  }
  bool started = false;
  bool any_stepping = false;
  for (std::size_t s = 0; s < 2; ++s) {
    IkState::Foot& f = state.foot[s];
    if (f.phase < 0.0) continue;
    f.phase += dt_s / std::max(f.duration_s, 1e-3);
    if (f.phase >= 1.0) {
      f.planted = f.land;
      f.yaw_rad = f.land_yaw_rad;
      f.turn_rad = wrap(pelvis_yaw_rad - f.yaw_rad);
      f.phase = -1.0;
    } else {
      any_stepping = true;
    }
  }
  if (!any_stepping) {
    // The foot furthest out of place (distance or turn, each over its
    // threshold) steps, if either is out.
    double worst = 1.0;
    int pick = -1;
    for (std::size_t s = 0; s < 2; ++s) {
      const IkState::Foot& f = state.foot[s];
      if (tracked[s]) continue;
      const double off = (horizontal(f.planted - under[s])).norm() / reach_out;
      const double turn = std::abs(f.turn_rad) / o.step_turn_rad;
      const double score = std::max(off, turn);
      if (score > worst) {
        worst = score;
        pick = static_cast<int>(s);
      }
    }
    if (pick >= 0) {
      IkState::Foot& f = state.foot[static_cast<std::size_t>(pick)];
      f.from = f.planted;
      f.from_yaw_rad = pelvis_yaw_rad - pivot_kept(f.turn_rad, pivot_start, pivot_width);
      f.phase = 0.0;
      const double fast = std::clamp(speed / 1.5, 0.0, 1.0);
      f.duration_s = o.step_time_s - fast * (o.step_time_s - o.step_time_min_s);
      // Where the foot's place will be when it lands, if the pelvis keeps its
      // velocity: a fixed point, so the foot comes down at rest.
      f.land = under[static_cast<std::size_t>(pick)] + (f.duration_s + o.step_lead_s) * v;
      f.land_yaw_rad = f.from_yaw_rad + wrap(pelvis_yaw_rad - f.from_yaw_rad);
      f.start_speed_mps = speed;
      started = true;
    }
  }
  for (std::size_t s = 0; s < 2; ++s) {
    IkState::Foot& f = state.foot[s];
    if (f.phase < 0.0) {
      out[s] = {f.planted, pelvis_yaw_rad - pivot_kept(f.turn_rad, pivot_start, pivot_width)};
      continue;
    }
    // The landing point follows its prediction from the pelvis's velocity now
    // (a walk that changes pace, turns or stops), less and less as the foot
    // comes down, so it lands at rest; all at once when the pelvis stops.
    const double left_s = (1.0 - f.phase) * f.duration_s;
    const sim::Vec3 predicted = under[s] + (left_s + o.step_lead_s) * v;
    f.land += first_order_share(dt_s, o.landing_follow_s) * (1.0 - f.phase) * (predicted - f.land);
    const double slowed = speed / std::max(f.start_speed_mps, kStopSpeedFloor_mps);
    f.land += smoothstep((kStopShareStart - slowed) / (kStopShareStart - kStopShareFull)) * (predicted - f.land);
    // The heading too, unwrapped as it goes: a body spinning past half a turn
    // from the foot must not flip the foot's turn to the other way round.
    f.land_yaw_rad += wrap(pelvis_yaw_rad - f.land_yaw_rad);
    const double k = swing_progress(f.phase);
    sim::Vec3 p = f.from + k * (f.land - f.from);
    // The lift keeps its quartic arc: the same push-brake bump has less jerk
    // in the limit but more at 30 Hz (measured).
    const double arc = 16.0 * f.phase * f.phase * (1.0 - f.phase) * (1.0 - f.phase);  // 1 at mid-step, flat ends
    p.z() += o.step_lift_m * arc;
    out[s] = {p, f.from_yaw_rad + k * (f.land_yaw_rad - f.from_yaw_rad)};
  }
  return started;
}

}  // namespace tonus::reference::detail
