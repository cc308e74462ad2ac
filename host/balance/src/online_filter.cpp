#include "tonus/host/balance/online_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <utility>

#include "constrained_preview.hpp"
#include "drop_envelope.hpp"
#include "tonus/host/balance/filter.hpp"
#include "tonus/host/balance/zmp.hpp"

namespace tonus::balance {
namespace {

constexpr double kMaxDrop_m = 0.008;
// How fast the drop follows its eased envelope (emit): measured 1.5, 2, 3
// and 4 Hz on the shared clips (docs/balance.md); 3 Hz, within a frame or two
// of the others' counts, has the smallest vertical accelerations at 30 Hz.
constexpr double kDropFollowHz = 3.0;
// The least weight of a frame's ZMP error (its support ratio, below).
constexpr double kMinErrorWeight = 0.2;
// The planner's support ratio: from that floor to this cap (a landing's
// impact; at 2 or 6 the clips' counts are within 5 frames of 3's).
constexpr double kMaxPlanRatio = 3.0;
// The most rows one frame gives the planner: its support polygon's edges (at
// most 12: each sole has two heel, two ball and two toe corners), the shift
// cap's 4 and the legs' 2. More would be dropped and counted by the planner.
constexpr std::size_t kRowsPerFrame = 18;
// Each leg's hip, knee and ankle.
constexpr std::array<std::array<std::size_t, 3>, 2> kLegJoints = {
    {{sim::index(sim::Bone::LeftUpperLeg), sim::index(sim::Bone::LeftLowerLeg), sim::index(sim::Bone::LeftFoot)},
     {sim::index(sim::Bone::RightUpperLeg), sim::index(sim::Bone::RightLowerLeg), sim::index(sim::Bone::RightFoot)}}};
// Beyond the planner's horizon, what every frame of the look-ahead asks is
// taken as held and priced by a Riccati cost-to-go of tracking weight Q + this
// share of the violation weight (constrained_preview.hpp). Measured with the
// violation weight 20 on a held 5 cm demand: Q + W/10 or less runs away (the
// plan pushes the violation past the horizon, frame after frame), Q + W/5
// settles (test_constrained_preview.cpp); on the clips a lower share is
// better (the whole weight: Bandai walk, worst member 100 against 89), so a
// quarter, with a margin from the edge.
constexpr double kHeldShare = 0.25;

bool finite_frame(const MotionFrame& f) {
  for (const Vec3& p : f.p) {
    if (!p.allFinite()) return false;
  }
  return true;
}

// The cart-table preview's options for the filter's rate, look-ahead and
// height, at a tracking weight.
PreviewOptions preview_options(const OnlineOptions& o, std::size_t lag, double tracking_weight) {
  PreviewOptions po;
  po.dt_s = o.dt_s;
  po.com_height_m = o.com_height_m;
  po.preview_frames = lag;
  po.tracking_weight = tracking_weight;
  po.jerk_weight = o.jerk_weight;
  po.gravity = o.analysis.gravity;
  return po;
}

// How much of a horizontal pelvis shift the whole body's centre of mass
// follows at this frame (the legs bend to keep the feet, so less than 1).
double shift_share(const MassModel& mass, const MotionFrame& f) {
  constexpr double kProbe_m = 0.01;
  const Vec3 c0 = centre_of_mass(mass, place_segments(mass, f.p));
  const Vec3 cx = centre_of_mass(mass, place_segments(mass, correct_waist(f, Vec3::Zero(), Vec2(kProbe_m, 0.0)).p));
  const double share = (cx.x() - c0.x()) / kProbe_m;
  return std::clamp(share, 0.3, 1.0);
}

}  // namespace

OnlineBalance::Created OnlineBalance::create(const OnlineOptions& o) {
  Created c;
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(o.dt_s)) {
    c.error = "dt_s must be finite and positive";
  } else if (!positive(o.lookahead_s) || o.lookahead_s > kMaxLookahead_s + 1e-12) {
    c.error = "the look-ahead must lie in (0, 0.25] s";
  } else if (!positive(o.margin_m) || !positive(o.max_shift_m) || !positive(o.jerk_weight) ||
             !positive(o.com_height_m)) {
    c.error = "margin, shift cap, jerk weight and centre-of-mass height must be finite and positive";
  } else if (!positive(o.window_cutoff_hz)) {
    c.error = "the window's cut-off must be finite and positive";
  } else if (!(std::isfinite(o.constraint_weight) && o.constraint_weight >= 0.0)) {
    c.error = "the constraint weight must be finite and not negative";
  } else if (!(o.max_fine_shift_m >= 0.0 && o.max_fine_shift_m <= o.max_shift_m)) {
    c.error = "the fine shift cap must lie in [0, shift cap]";
  }
  if (!c.error.empty()) return c;
  const auto lag = static_cast<std::size_t>(std::lround(o.lookahead_s / o.dt_s));
  if (lag < 1) {
    c.error = "the look-ahead is shorter than one frame";
    return c;
  }
  derivatives::Params p = o.analysis.derivatives;
  p.method = derivatives::Method::kalman;  // the fixed-lag form of both Kalman methods
  p.cutoff_hz = o.window_cutoff_hz;
  auto smoother = derivatives::FixedLag3::create(o.dt_s, p, lag);
  if (!smoother) {
    c.error = "smoothing: " + std::string(derivatives::to_string(smoother.status.error));
    return c;
  }
  PreviewModel preview = preview_model(preview_options(o, lag, 1.0));
  if (!preview.ok()) {
    c.error = "preview control: " + preview.error;
    return c;
  }
  c.filter.emplace(OnlineBalance(o, lag, *smoother.smoother, std::move(preview)));
  return c;
}

OnlineBalance::OnlineBalance(const OnlineOptions& options, std::size_t lag, const derivatives::FixedLag3& smoother,
                             PreviewModel preview)
    : options_(options),
      lag_(lag),
      mass_(make_mass_model(options.analysis.body_mass_kg, options.analysis.sex, options.analysis.trunk)),
      contacts_(options.analysis.contacts, options.dt_s),
      segments_(kSegmentParts, smoother),
      preview_(std::move(preview)),
      frames_(lag + 1),
      frame_contacts_(lag + 1),
      placed_(lag + 1),
      polygons_(lag + 1),
      window_(kSegmentParts * (lag + 1)),
      zmp_(lag + 1, Vec2::Zero()),
      ratio_(lag + 1, 1.0),
      outside_(lag + 1, 0.0),
      defined_(lag + 1, false) {
  drop_envelope_ = std::make_unique<detail::DropEnvelope>(options.dt_s, lag);
  past_need_.assign(drop_envelope_->reach() + 1, 0.0);
  need_window_.assign(2 * drop_envelope_->reach() + 1, 0.0);
  for (ConvexPolygon& p : polygons_) p.vertices.reserve(kHullInlinePoints);
  errors_[0].assign(lag + 1, 0.0);
  errors_[1].assign(lag + 1, 0.0);
  if (options.constraint_weight > 0.0) {
    const PreviewModel held =
        preview_model(preview_options(options, lag, 1.0 + kHeldShare * options.constraint_weight));
    planner_ =
        std::make_unique<detail::ConstrainedPreview>(preview_, held.ok() ? held.P : preview_.P, lag, 1.0,
                                                     options.jerk_weight, options.constraint_weight, kRowsPerFrame);
  }
}

OnlineBalance::OnlineBalance(OnlineBalance&&) noexcept = default;
OnlineBalance& OnlineBalance::operator=(OnlineBalance&&) noexcept = default;
OnlineBalance::~OnlineBalance() = default;

bool OnlineBalance::push(const MotionFrame& in, OnlineFrame& out) {
  const std::size_t slot = pushed_ % (lag_ + 1);
  if (finite_frame(in) || pushed_ == 0) {
    frames_[slot] = in;
  } else {
    frames_[slot] = frames_[(pushed_ - 1) % (lag_ + 1)];
    ++non_finite_;
  }
  const MotionFrame& f = frames_[slot];
  frame_contacts_[slot] = contacts_.push(f);
  const auto& c = frame_contacts_[slot];
  if (c[0].any() || c[1].any())
    support_polygon(contacts_.track(), f, c, polygons_[slot]);
  else
    polygons_[slot].vertices.clear();
  placed_[slot] = place_segments(mass_, f.p);
  const SegmentFrame& seg = placed_[slot];
  for (std::size_t i = 0; i < kSegmentParts; ++i) segments_[i].push(seg[i].com);
  ++pushed_;
  if (pushed_ <= lag_) return false;
  window_errors();
  emit(lag_, out);
  return true;
}

bool OnlineBalance::flush(OnlineFrame& out) {
  if (pushed_ == 0 || emitted_ >= pushed_) return false;
  const std::size_t back = pushed_ - 1 - emitted_;  // frames between it and the newest
  window_errors();
  emit(back, out);
  return true;
}

// The ZMP error of every frame in the window, from the smoothers' current
// estimates (the newest frame at frames_back 0).
void OnlineBalance::window_errors() {
  const std::size_t held = std::min(pushed_, lag_ + 1);
  const double g = options_.analysis.gravity;
  const double ground = contacts_.track().ground_z_m;
  SegmentFrame seg{};
  std::array<Vec3, kSegmentParts> acc{};
  // Each smoother's whole window in one backward pass.
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    segments_[i].estimate_window(std::span<derivatives::Estimate3>(window_.data() + i * (lag_ + 1), held));
  }
  for (std::size_t w = 0; w < held; ++w) {  // w = 0: the oldest held
    const std::size_t back = held - 1 - w;
    const std::size_t k = pushed_ - 1 - back;
    const SegmentFrame& placed = placed_[k % (lag_ + 1)];
    bool valid = true;
    for (std::size_t i = 0; i < kSegmentParts; ++i) {
      const derivatives::Estimate3& e = window_[i * (lag_ + 1) + back];
      valid = valid && e.valid;
      seg[i] = placed[i];
      seg[i].com = e.valid ? e.pos : placed[i].com;
      acc[i] = e.valid ? e.acc : Vec3::Zero();
    }
    ZmpInputs zi;
    zi.segments = &seg;
    zi.accel = &acc;
    const ZmpResult z = zero_moment_point(mass_, zi, ground, g);
    errors_[0][w] = errors_[1][w] = 0.0;
    defined_[w] = valid && z.defined;
    ratio_[w] = std::clamp(z.support_ratio, kMinErrorWeight, kMaxPlanRatio);
    zmp_[w] = z.zmp;
    outside_[w] = 0.0;
    const ConvexPolygon& poly = polygons_[k % (lag_ + 1)];
    if (!defined_[w] || poly.vertices.empty()) continue;
    outside_[w] = signed_distance(poly, z.zmp);
    if (outside_[w] > -options_.margin_m) {
      const Vec2 target = nearest_point_inset(poly, z.zmp, options_.margin_m);
      // Where the feet carry only part of the weight (a bounce's trough), a
      // shift's acceleration moves the ZMP by the inverse of that share, and
      // the estimators disagree most: the cart asks for the share of the move
      // (the plain preview's weight: the support ratio, at most 1).
      const double weight = std::min(ratio_[w], 1.0);
      errors_[0][w] = weight * (target.x() - z.zmp.x());
      errors_[1][w] = weight * (target.y() - z.zmp.y());
    }
  }
}

// Emits the frame `frames_back` before the newest; the window's position of
// it is held - 1 - frames_back.
void OnlineBalance::emit(std::size_t frames_back, OnlineFrame& out) {
  const std::size_t held = std::min(pushed_, lag_ + 1);
  const std::size_t w = held - 1 - frames_back;
  const std::size_t k = pushed_ - 1 - frames_back;
  const MotionFrame& f = frames_[k % (lag_ + 1)];
  const Vec2 offset(cart_[0].x(), cart_[1].x());
  if (share_ <= 0.0) share_ = shift_share(mass_, f);  // once: it jumps where a leg straightens
  const double share = share_;
  Vec2 shift = offset / share;
  out.shift_capped = false;
  for (Eigen::Index a = 0; a < 2; ++a) {
    if (std::abs(shift[a]) > options_.max_shift_m) {
      shift[a] = std::copysign(options_.max_shift_m, shift[a]);
      out.shift_capped = true;
    }
  }
  // The fine layer (fine_shift, below): the capture's jitter out of what the ZMP sees.
  Vec2 fine = Vec2::Zero();
  if (options_.max_fine_shift_m > 0.0) {
    SegmentFrame smoothed = placed_[k % (lag_ + 1)];
    bool valid = true;
    for (std::size_t i = 0; i < kSegmentParts; ++i) {
      const derivatives::Estimate3& e = window_[i * (lag_ + 1) + frames_back];
      valid = valid && e.valid;
      if (e.valid) smoothed[i].com = e.pos;
    }
    if (valid) fine = fine_shift(f, placed_[k % (lag_ + 1)], smoothed, shift);
  }
  shift += fine;
  bool reachable = true;
  double need = waist_turn(f, Vec3::Zero(), shift).drop_m;
  // A straight stance leg makes the pelvis drop to keep its foot; more than
  // a few millimetres is a plunge. Shift less there instead.
  if (need > kMaxDrop_m) {
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 6; ++i) {
      const double mid = 0.5 * (lo + hi);
      (waist_turn(f, Vec3::Zero(), mid * shift).drop_m > kMaxDrop_m ? hi : lo) = mid;
    }
    shift *= lo;
    out.shift_capped = true;
    need = waist_turn(f, Vec3::Zero(), shift).drop_m;
  }
  // The drop comes and goes with a leg's straightening, within a frame or
  // two: eased over the frames either side (drop_envelope.hpp), the needs of
  // the ones already out as they went out, of the ones ahead under this shift.
  const std::size_t reach = drop_envelope_->reach();
  for (std::size_t j = 0; j < need_window_.size(); ++j) {
    double v = 0.0;
    if (j < reach) {  // before this frame: the need it went out with
      const std::size_t back = reach - j;
      if (back <= emitted_) v = past_need_[(emitted_ - back) % past_need_.size()];
    } else if (j == reach) {
      v = need;
    } else if (j - reach <= frames_back) {  // ahead, within what has arrived, under this shift
      v = waist_turn(frames_[(k + (j - reach)) % (lag_ + 1)], Vec3::Zero(), shift).drop_m;
    }
    need_window_[j] = std::max(v, 0.0);
  }
  past_need_[emitted_ % past_need_.size()] = std::max(need, 0.0);
  // The needs ahead are foreseen under this frame's shift, and the shift
  // moves on: a need foreseen on one frame may be gone on the next. The drop
  // follows that envelope as a critically damped second-order system (exact
  // steps), so a need foreseen for a frame or two moves it little; never
  // below this frame's own need (the foot is kept), and from rest where that
  // forces it.
  const double target = drop_envelope_->at(need_window_.data(), need_window_.size(), reach);
  double eased = target;
  if (emitted_ > 0) {
    const double omega = 2.0 * std::numbers::pi * kDropFollowHz, dt = options_.dt_s;
    const double e0 = drop_state_[0] - target, v0 = drop_state_[1], b = v0 + omega * e0;
    const double decay = std::exp(-omega * dt);
    eased = target + (e0 + b * dt) * decay;
    drop_state_[1] = (v0 - omega * b * dt) * decay;
    if (need > eased) {
      eased = need;
      drop_state_[1] = 0.0;
    }
  }
  drop_state_[0] = eased;
  out.corrected = correct_waist(f, Vec3::Zero(), shift, &out.drop_m, &reachable, {}, eased);
  // Anti-windup: where the cap or the leg's reach held the shift back, the
  // cart goes on from where the body is, not from where it was asked to be
  // (else it overshoots when the limit lets go, which is a jolt).
  const Vec2 applied = (shift - fine) * share;
  for (std::size_t a = 0; a < 2; ++a) {
    if (options_.anti_windup) cart_[a].x() = applied[static_cast<Eigen::Index>(a)];
  }
  if (planner_) {
    plan_rows(w, held);
    planner_->step(cart_);
  } else {
    for (std::size_t a = 0; a < 2; ++a) {
      // The errors after this frame (at least one: the last is held).
      const std::size_t first = std::min(w + 1, held - 1);
      const std::span<const double> ahead(errors_[a].data() + first, held - first);
      preview_step(preview_, cart_[a], ahead);
    }
  }
  out.share = share;
  out.index = k;
  out.shift_m = shift;
  out.fine_shift_m = fine;
  out.contacts = frame_contacts_[k % (lag_ + 1)];
  out.zmp_defined = defined_[w];
  out.zmp_before = zmp_[w];
  out.outside_before_m = outside_[w];
  out.reachable = reachable;
  ++emitted_;
}

// The fine layer's shift: the ZMP's acceleration term is sum_i m_i (z_i -
// ground) a_i, so the capture's jitter weighs by each segment's height; a
// pelvis shift moves each segment by its own share (the trunk, arms and head
// fully, the legs in part, the feet not). The shift that moves that
// height-weighted sum by the smoothers' estimate minus the capture is the
// difference over the height-weighted share, per axis, within the cap.
Vec2 OnlineBalance::fine_shift(const MotionFrame& f, const SegmentFrame& captured, const SegmentFrame& smoothed,
                               const Vec2& shift) const {
  constexpr double kProbe_m = 1e-3;
  const double ground = contacts_.track().ground_z_m;
  const SegmentFrame at = place_segments(mass_, correct_waist(f, Vec3::Zero(), shift).p);
  std::array<SegmentFrame, 2> moved;
  for (Eigen::Index a = 0; a < 2; ++a) {
    Vec2 probe = shift;
    probe[a] += kProbe_m;
    moved[static_cast<std::size_t>(a)] = place_segments(mass_, correct_waist(f, Vec3::Zero(), probe).p);
  }
  Vec2 wanted = Vec2::Zero(), moves = Vec2::Zero();
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    const double w = mass_.parts[i].mass_kg * std::max(captured[i].com.z() - ground, 0.0);
    wanted += w * (smoothed[i].com - captured[i].com).head<2>();
    for (Eigen::Index a = 0; a < 2; ++a)
      moves[a] += w * (moved[static_cast<std::size_t>(a)][i].com[a] - at[i].com[a]) / kProbe_m;
  }
  Vec2 fine = Vec2::Zero();
  for (Eigen::Index a = 0; a < 2; ++a) {
    if (moves[a] > 1e-9)
      fine[a] = std::clamp(wanted[a] / moves[a], -options_.max_fine_shift_m, options_.max_fine_shift_m);
  }
  return fine;
}

// The planner's half-planes for the frames after window position w: each
// edge of a frame's support polygon bounds the ZMP's move m by
// n . (z + m) <= n . edge - margin, m = x - z_c / g * xdd / r for the offset
// x and the frame's support ratio r (where the feet carry part of the
// weight, the offset's acceleration moves the ZMP further; at a landing's
// impact, less), as r times it (ConstrainedPreview::set_support_ratio).
// Beyond the newest frame the newest is held.
void OnlineBalance::plan_rows(std::size_t w, std::size_t held) {
  using Bounds = detail::ConstrainedPreview::Bounds;
  constexpr double kFarEnough_m = 0.25;  // an edge this far beyond what a move can reach cannot bind
  planner_->clear_rows();
  for (std::size_t s = 1; s <= planner_->horizon(); ++s) {
    const std::size_t pos = std::min(w + s, held - 1);
    const std::size_t k = pushed_ - held + pos;
    // The offset, as the pelvis shift it asks for (divided by the share the
    // centre of mass follows): within the cap, and within each leg's reach of
    // its ankle with the pelvis lowered by at most the drop allowed (the
    // reach's disc taken by its tangent).
    const double cap = options_.max_shift_m * share_;
    for (const Vec2& axis : {Vec2(1.0, 0.0), Vec2(0.0, 1.0)}) {
      planner_->add_row(s, Bounds::offset, axis, cap);
      planner_->add_row(s, Bounds::offset, -axis, cap);
    }
    const MotionFrame& f = frames_[k % (lag_ + 1)];
    for (const auto& leg : kLegJoints) {
      const Vec3 hip = f.p[leg[0]], knee = f.p[leg[1]], ankle = f.p[leg[2]];
      const double reach = leg_reach_m(hip, knee, ankle);
      const double height = std::max(hip.z() - ankle.z() - kMaxDrop_m, 0.0);
      const double across = std::sqrt(std::max(reach * reach - height * height, 0.0));
      const Vec2 out = (hip - ankle).head<2>();
      const double dist = out.norm();
      if (dist < 1e-6 || across - dist > kFarEnough_m) continue;
      planner_->add_row(s, Bounds::offset, out / dist, share_ * (across - dist));
    }
    if (!defined_[pos]) continue;
    const ConvexPolygon& poly = polygons_[k % (lag_ + 1)];
    const Vec2 z = zmp_[pos];
    // The offset moves the ZMP by itself, its acceleration by z_c / g over
    // the support ratio: the rows bound the ratio times that move.
    const double ratio = ratio_[pos];
    planner_->set_support_ratio(s, ratio);
    if (poly.vertices.size() >= 3) {
      for (std::size_t i = 0; i < poly.vertices.size(); ++i) {
        const Vec2& p0 = poly.vertices[i];
        const Vec2& p1 = poly.vertices[(i + 1) % poly.vertices.size()];
        const Vec2 edge = p1 - p0;
        const double len = edge.norm();
        if (len < 1e-9) continue;
        const Vec2 normal(edge.y() / len, -edge.x() / len);  // outward: the vertices run counter-clockwise
        const double bound = ratio * (normal.dot(p0) - options_.margin_m - normal.dot(z));
        if (bound < kFarEnough_m) planner_->add_row(s, Bounds::zmp, normal, bound);
      }
    } else if (!poly.vertices.empty()) {
      // A point or a segment: toward its nearest point.
      const Vec2 target = nearest_point_inset(poly, z, options_.margin_m);
      const Vec2 away = z - target;
      const double dist = away.norm();
      if (dist > 1e-9) planner_->add_row(s, Bounds::zmp, away / dist, -ratio * dist);
    }
  }
}

}  // namespace tonus::balance
