// Foot contacts, soles and support polygons. The proportions (heel 23 % of the
// foot length behind the ankle, the ball 56 % and the toe tip 77 % in front of
// it, breadth 38 % of the length) are Winter's (2009) foot geometry, the one
// the physics humanoid uses too; see docs/balance.md.
#include "tonus/host/balance/contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tonus::balance {
namespace {

constexpr double kHeelBehindAnkle = 0.23;   // of the foot length
constexpr double kBallAheadOfAnkle = 0.56;  // of the foot length
constexpr double kTipAheadOfAnkle = 0.77;
constexpr double kBreadth = 0.38;
constexpr double kSoleBelowLowestPoint = 0.02;  // tracked foot points sit ~2 cm above the sole
constexpr double kRearFootShare = 0.25;         // heel-only contact: the rear quarter of the sole supports

Vec2 horizontal(const Vec3& v) { return {v.x(), v.y()}; }

Quat foot_rotation(const MotionFrame& fr, Foot foot) {
  return fr.rotation[sim::index(foot == Foot::left ? sim::Bone::LeftFoot : sim::Bone::RightFoot)];
}

// How flat a foot stands: low ankle and ball, slow (lower is flatter); the
// offline detection takes its sole from the flattest frame, the causal one
// from the flattest so far.
double flatness(const Vec3& ankle, const Vec3& ball, double speed_mps) {
  return ankle.z() + ball.z() + 0.05 * speed_mps;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// The frame where the foot stands flattest: ankle and ball low and slow.
std::size_t flat_frame(const HumanMotion& m, const FootLandmarks& f) {
  std::size_t best = m.first_frame;
  double best_score = std::numeric_limits<double>::infinity();
  for (std::size_t t = std::max<std::size_t>(m.first_frame, 1); t + 1 < m.size(); ++t) {
    const auto& a = m.frames[t].p;
    const double speed = ((m.frames[t + 1].p[index(f.ankle)] - m.frames[t - 1].p[index(f.ankle)]).norm() +
                          (m.frames[t + 1].p[index(f.toe_joint)] - m.frames[t - 1].p[index(f.toe_joint)]).norm()) /
                         (2.0 * m.dt_s);
    const double score = flatness(a[index(f.ankle)], a[index(f.toe_joint)], speed);
    if (score < best_score) {
      best_score = score;
      best = t;
    }
  }
  return best;
}

}  // namespace

Sole measure_sole(const MotionFrame& fr, Foot foot, double ground_z, const ContactOptions& opt) {
  const FootLandmarks f = foot_landmarks(foot);
  const Vec3 ankle = fr.p[index(f.ankle)], ball = fr.p[index(f.toe_joint)], tip = fr.p[index(f.toe_tip)];
  Vec2 fwd = horizontal(ball - ankle);
  if (fwd.norm() < 1e-6) fwd = Vec2(1, 0);
  const double ball_ahead = fwd.norm();
  fwd.normalize();
  const Vec2 side(-fwd.y(), fwd.x());
  // Foot length: Winter's 0.152 of the stature, the stature from the leg
  // (hip to ankle 0.491 of it); longer if the skeleton's toe tip says so.
  // (Skeletons place the toe joint anywhere from mid-foot to the ball, so it
  // does not give the length.)
  const Landmark hip = foot == Foot::left ? joint_of(sim::Bone::LeftUpperLeg) : joint_of(sim::Bone::RightUpperLeg);
  const Landmark knee = foot == Foot::left ? joint_of(sim::Bone::LeftLowerLeg) : joint_of(sim::Bone::RightLowerLeg);
  const double leg = (fr.p[index(knee)] - fr.p[index(hip)]).norm() + (ankle - fr.p[index(knee)]).norm();
  double length = 0.152 / 0.491 * leg;
  const double tip_ahead = horizontal(tip - ankle).dot(fwd);
  if (tip_ahead > ball_ahead + 0.01) length = std::max(length, tip_ahead / kTipAheadOfAnkle);
  if (opt.foot_length_m) length = *opt.foot_length_m;
  Sole s;
  s.length_m = length;
  s.width_m = kBreadth * length;
  const auto on_ground = [&](const Vec2& p) { return Vec3(p.x(), p.y(), ground_z); };
  const Vec2 a2 = horizontal(ankle);
  const Vec2 heel = a2 - kHeelBehindAnkle * length * fwd;
  const Vec2 ball2 = a2 + kBallAheadOfAnkle * length * fwd;
  const Vec2 tip2 = a2 + kTipAheadOfAnkle * length * fwd;
  const Quat foot_rot = foot_rotation(fr, foot);
  const Quat toes_rot = fr.rotation[sim::index(foot == Foot::left ? sim::Bone::LeftToes : sim::Bone::RightToes)];
  const auto in_foot = [&](const Vec2& p) { return Vec3(foot_rot.conjugate() * (on_ground(p) - ankle)); };
  const auto in_toes = [&](const Vec2& p) { return Vec3(toes_rot.conjugate() * (on_ground(p) - ball)); };
  const double w = s.width_m;
  s.rear = {in_foot(heel + 0.4 * w * side), in_foot(heel - 0.4 * w * side)};
  s.ball = {in_foot(ball2 + 0.5 * w * side), in_foot(ball2 - 0.5 * w * side)};
  s.toes = {in_toes(tip2 + 0.3 * w * side), in_toes(tip2 - 0.3 * w * side)};
  return s;
}

namespace {

struct SoleWorld {
  std::vector<Vec3> rear, ball, toes;
};

// Where a foot's sole is at a frame: its rear and ball corners ride on the
// foot (from the ankle), its toe corners on the toes (from the toe joint).
struct SolePose {
  Quat foot_rot, toes_rot;
  Vec3 ankle, ball;
  [[nodiscard]] Vec3 on_foot(const Vec3& p) const { return ankle + foot_rot * p; }
  [[nodiscard]] Vec3 on_toes(const Vec3& p) const { return ball + toes_rot * p; }
};

SolePose sole_pose(const MotionFrame& fr, Foot foot) {
  const FootLandmarks f = foot_landmarks(foot);
  return {foot_rotation(fr, foot),
          fr.rotation[sim::index(foot == Foot::left ? sim::Bone::LeftToes : sim::Bone::RightToes)],
          fr.p[index(f.ankle)], fr.p[index(f.toe_joint)]};
}

SoleWorld place(const Sole& s, const MotionFrame& fr, Foot foot) {
  const SolePose pose = sole_pose(fr, foot);
  SoleWorld w;
  for (const Vec3& p : s.rear) w.rear.push_back(pose.on_foot(p));
  for (const Vec3& p : s.ball) w.ball.push_back(pose.on_foot(p));
  for (const Vec3& p : s.toes) w.toes.push_back(pose.on_toes(p));
  return w;
}

Vec3 mean(const std::vector<Vec3>& v) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& p : v) c += p;
  return v.empty() ? c : Vec3(c / static_cast<double>(v.size()));
}

// The point's resting height around each frame: a low percentile of its
// heights within +-kRestWindow_s, so a floor that is not quite level (a take
// whose stance foot creeps up a few centimetres) is followed.
constexpr double kRestWindow_s = 1.5;
// How long a point must stand still to land above its `on` height (below).
constexpr double kStillLanded_s = 0.05;
constexpr double kFlatFoot_m = 0.01;  // a still foot's heel and ball this close in height stand flat

std::vector<double> resting_height(const std::vector<double>& height, std::size_t first, double dt) {
  const auto half = static_cast<std::size_t>(kRestWindow_s / dt);
  std::vector<double> rest(height.size(), 0.0), window;
  for (std::size_t t = 0; t < height.size(); ++t) {
    const std::size_t lo = std::max(first, t > half ? t - half : 0), hi = std::min(height.size(), t + half + 1);
    window.assign(height.begin() + static_cast<std::ptrdiff_t>(std::min(lo, hi - 1)),
                  height.begin() + static_cast<std::ptrdiff_t>(hi));
    rest[t] = percentile(window, 0.05);
  }
  return rest;
}

// One point's series over the clip, and the frames within a run of still
// frames (slower than speed_on) at least kStillLanded_s long.
struct PointSeries {
  std::vector<double> height, speed, rest;
  std::vector<bool> still;
};

// Whether a point that is up lands although above its `on` height: still for
// kStillLanded_s and under its `off` height, and its foot otherwise up, or its
// foot's other point also still at the same height (a flat foot on a floor
// higher than the resting heights say: a floor that rises along the take).
bool lands_still(double h, bool still, double other_h, bool other_still, bool foot_up, const ContactOptions& o) {
  if (!still || h >= o.height_off_m) return false;
  return foot_up || (other_still && std::abs(h - other_h) < kFlatFoot_m);
}

// A point's contact after this frame: it stays down until it rises above the
// `off` height or moves faster than the `off` speed; it lands when low and
// slow, or by the still-landing rule (`landed`, above). Offline and causal alike.
bool next_contact(bool on, double h, double speed, bool landed, const ContactOptions& o) {
  if (on) return !(h > o.height_off_m || speed > o.speed_off_mps);
  return (h < o.height_on_m && speed < o.speed_on_mps) || landed;
}

// Low-and-slow with hysteresis over the heel's and the ball's series, with
// the still-landing rule above.
std::array<std::vector<bool>, 2> foot_hysteresis(const std::array<PointSeries, 2>& pts, std::size_t first,
                                                 const ContactOptions& o) {
  const std::size_t n = pts[0].height.size();
  std::array<std::vector<bool>, 2> on{std::vector<bool>(n, false), std::vector<bool>(n, false)};
  std::array<bool, 2> state{false, false};
  for (std::size_t t = first; t < n; ++t) {
    const bool foot_up = !state[0] && !state[1];
    const std::array<double, 2> h{pts[0].height[t] - pts[0].rest[t], pts[1].height[t] - pts[1].rest[t]};
    for (std::size_t k = 0; k < 2; ++k) {
      const PointSeries& p = pts[k];
      const bool landed = lands_still(h[k], p.still[t], h[1 - k], pts[1 - k].still[t], foot_up, o);
      state[k] = next_contact(state[k], h[k], p.speed[t], landed, o);
      on[k][t] = state[k];
    }
  }
  return on;
}

std::vector<bool> still_runs(const std::vector<double>& speed, std::size_t first, double dt, const ContactOptions& o) {
  std::vector<bool> still(speed.size(), false);
  const auto need = static_cast<std::size_t>(std::ceil(kStillLanded_s / dt - 1e-9));
  for (std::size_t t = first; t < speed.size();) {
    std::size_t e = t;
    while (e < speed.size() && speed[e] < o.speed_on_mps) ++e;
    if (e - t >= need)
      std::fill(still.begin() + static_cast<std::ptrdiff_t>(t), still.begin() + static_cast<std::ptrdiff_t>(e), true);
    t = e == t ? t + 1 : e;
  }
  return still;
}

}  // namespace

ContactTrack detect_contacts(const HumanMotion& m, const ContactOptions& opt) {
  ContactTrack track;
  track.frames.assign(m.size(), {});
  if (m.size() < 3 || m.size() <= m.first_frame) return track;
  // Ground: just below the lowest tracked foot points when they rest.
  if (opt.ground_z_m) {
    track.ground_z_m = *opt.ground_z_m;
  } else {
    std::vector<double> lows;
    for (std::size_t t = m.first_frame; t < m.size(); ++t) {
      double low = std::numeric_limits<double>::infinity();
      for (const Foot foot : {Foot::left, Foot::right}) {
        const FootLandmarks f = foot_landmarks(foot);
        for (const Landmark l : {f.ankle, f.toe_joint, f.toe_tip}) low = std::min(low, m.frames[t].p[index(l)].z());
      }
      lows.push_back(low);
    }
    track.ground_z_m = percentile(lows, 0.05) - kSoleBelowLowestPoint;
  }
  for (const Foot foot : {Foot::left, Foot::right}) {
    const auto fi = static_cast<std::size_t>(foot);
    track.soles[fi] = measure_sole(m.frames[flat_frame(m, foot_landmarks(foot))], foot, track.ground_z_m, opt);
    // Heights and speeds of the heel and the ball over the clip.
    std::vector<Vec3> heel(m.size()), ball(m.size());
    for (std::size_t t = 0; t < m.size(); ++t) {
      const SoleWorld w = place(track.soles[fi], m.frames[t], foot);
      heel[t] = mean(w.rear);
      ball[t] = mean(w.ball);
    }
    // Central differences within the motion, each end taking its neighbour's
    // (two frames: the one difference); a leading T-pose is not a neighbour.
    const auto speeds = [&](const std::vector<Vec3>& p) {
      std::vector<double> v(p.size(), 0.0);
      const std::size_t lo = m.first_frame, hi = p.size() - 1;
      if (hi - lo >= 2) {
        for (std::size_t t = lo + 1; t < hi; ++t) v[t] = (p[t + 1] - p[t - 1]).norm() / (2.0 * m.dt_s);
        v[lo] = v[lo + 1];
        v[hi] = v[hi - 1];
      } else if (hi > lo) {
        v[lo] = v[hi] = (p[hi] - p[lo]).norm() / m.dt_s;
      }
      for (std::size_t t = 0; t < lo; ++t) v[t] = v[lo];
      return v;
    };
    const auto heights = [&](const std::vector<Vec3>& p) {
      std::vector<double> h(p.size());
      for (std::size_t t = 0; t < p.size(); ++t) h[t] = p[t].z();
      return h;
    };
    std::array<PointSeries, 2> pts;
    for (std::size_t k = 0; k < 2; ++k) {
      const std::vector<Vec3>& p = k == 0 ? heel : ball;
      pts[k].height = heights(p);
      pts[k].speed = speeds(p);
      pts[k].rest = resting_height(pts[k].height, m.first_frame, m.dt_s);
      pts[k].still = still_runs(pts[k].speed, m.first_frame, m.dt_s, opt);
    }
    const auto on = foot_hysteresis(pts, m.first_frame, opt);
    for (std::size_t t = 0; t < m.size(); ++t) track.frames[t][fi] = {on[0][t], on[1][t]};
  }
  return track;
}

ConvexPolygon support_polygon(const ContactTrack& track, const MotionFrame& frame, std::size_t t) {
  return support_polygon(track, frame, track.frames[t]);
}

namespace {

// The supporting points of both feet (the parts of each sole under its
// touching points), each handed to `add` in the ground plane.
template <class Add>
void supporting_points(const ContactTrack& track, const MotionFrame& frame, const std::array<FootContact, 2>& contacts,
                       Add add) {
  for (const Foot foot : {Foot::left, Foot::right}) {
    const auto fi = static_cast<std::size_t>(foot);
    const FootContact c = contacts[fi];
    if (!c.any()) continue;
    const Sole& sole = track.soles[fi];
    const SolePose pose = sole_pose(frame, foot);
    if (c.ball) {
      for (const Vec3& p : sole.ball) add(horizontal(pose.on_foot(p)));
      for (const Vec3& p : sole.toes) add(horizontal(pose.on_toes(p)));
    }
    if (c.heel) {
      for (const Vec3& p : sole.rear) add(horizontal(pose.on_foot(p)));
      if (!c.ball) {  // heel strike: the rear of the sole
        const double share = kRearFootShare / (kHeelBehindAnkle + kBallAheadOfAnkle);
        for (std::size_t k = 0; k < sole.rear.size() && k < sole.ball.size(); ++k) {
          const Vec3 rear = pose.on_foot(sole.rear[k]), front = pose.on_foot(sole.ball[k]);
          add(horizontal(rear + share * (front - rear)));
        }
      }
    }
  }
}

}  // namespace

void support_polygon(const ContactTrack& track, const MotionFrame& frame, const std::array<FootContact, 2>& contacts,
                     ConvexPolygon& out) {
  std::array<Vec2, kHullInlinePoints> inline_points;
  std::size_t n = 0;
  bool overflow = false;
  supporting_points(track, frame, contacts, [&](const Vec2& p) {
    if (n < inline_points.size())
      inline_points[n++] = p;
    else
      overflow = true;
  });
  if (!overflow) {
    convex_hull(std::span<const Vec2>(inline_points.data(), n), out);
    return;
  }
  // Soles with more corners than fit (not the measured ones): on the heap.
  std::vector<Vec2> pts;
  supporting_points(track, frame, contacts, [&](const Vec2& p) { pts.push_back(p); });
  convex_hull(pts, out);
}

ConvexPolygon support_polygon(const ContactTrack& track, const MotionFrame& frame,
                              const std::array<FootContact, 2>& contacts) {
  ConvexPolygon out;
  support_polygon(track, frame, contacts, out);
  return out;
}

std::vector<Vec2> sole_outline(const ContactTrack& track, const MotionFrame& frame, Foot foot) {
  const SoleWorld w = place(track.soles[static_cast<std::size_t>(foot)], frame, foot);
  std::vector<Vec2> pts;
  for (const auto* part : {&w.rear, &w.ball, &w.toes}) {
    for (const Vec3& p : *part) pts.push_back(horizontal(p));
  }
  return convex_hull(pts).vertices;
}

CausalContacts::CausalContacts(const ContactOptions& options, double dt_s)
    : options_(options),
      dt_s_(dt_s),
      window_(std::max<std::size_t>(3, static_cast<std::size_t>(kRestWindow_s / dt_s))) {
  lows_.assign(window_, 0.0);
  for (auto& foot : points_) {
    for (Point& p : foot) p.heights.assign(window_, 0.0);
  }
  scratch_.reserve(window_);
  flattest_.fill(std::numeric_limits<double>::infinity());
}

double CausalContacts::percentile_of(const std::vector<double>& ring) const {
  const std::size_t n = std::min(pushed_, window_);
  scratch_.assign(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(n));
  const auto k = static_cast<std::size_t>(0.05 * static_cast<double>(n - 1));
  std::nth_element(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(k), scratch_.end());
  return scratch_[k];
}

std::array<FootContact, 2> CausalContacts::push(const MotionFrame& frame) {
  const std::size_t slot = pushed_ % window_;
  double low = std::numeric_limits<double>::infinity();
  for (const Foot foot : {Foot::left, Foot::right}) {
    const FootLandmarks f = foot_landmarks(foot);
    for (const Landmark l : {f.ankle, f.toe_joint, f.toe_tip}) low = std::min(low, frame.p[index(l)].z());
  }
  lows_[slot] = low;
  ++pushed_;
  track_.ground_z_m = options_.ground_z_m ? *options_.ground_z_m : percentile_of(lows_) - kSoleBelowLowestPoint;

  std::array<FootContact, 2> out{};
  for (const Foot foot : {Foot::left, Foot::right}) {
    const auto fi = static_cast<std::size_t>(foot);
    const FootLandmarks f = foot_landmarks(foot);
    const Vec3 ankle = frame.p[index(f.ankle)], ball = frame.p[index(f.toe_joint)];
    // Re-measure the sole on a flatter stance than any so far.
    const double speed =
        pushed_ > 1 ? ((ankle - last_ankle_[fi]).norm() + (ball - last_ball_[fi]).norm()) / dt_s_ : 0.0;
    const double score = flatness(ankle, ball, speed);
    if (score < flattest_[fi]) {
      flattest_[fi] = score;
      track_.soles[fi] = measure_sole(frame, foot, track_.ground_z_m, options_);
      ++soles_measured_;
    }
    last_ankle_[fi] = ankle;
    last_ball_[fi] = ball;

    const Quat foot_rot = foot_rotation(frame, foot);
    const std::array<Vec3, 2> now = {Vec3(ankle + foot_rot * mean(track_.soles[fi].rear)),
                                     Vec3(ankle + foot_rot * mean(track_.soles[fi].ball))};
    std::array<double, 2> h{}, v{};
    for (std::size_t k = 0; k < 2; ++k) {
      Point& p = points_[fi][k];
      p.heights[slot] = now[k].z();
      h[k] = now[k].z() - percentile_of(p.heights);
      v[k] = pushed_ > 2 ? (now[k] - p.before_last).norm() / (2.0 * dt_s_)
                         : (pushed_ > 1 ? (now[k] - p.last).norm() / dt_s_ : 0.0);
      p.still = v[k] < options_.speed_on_mps ? p.still + 1 : 0;
    }
    const bool foot_up = !points_[fi][0].on && !points_[fi][1].on;
    const auto still = [&](const Point& q) { return static_cast<double>(q.still) * dt_s_ >= kStillLanded_s; };
    std::array<bool, 2> on{};
    for (std::size_t k = 0; k < 2; ++k) {
      Point& p = points_[fi][k];
      const bool landed = lands_still(h[k], still(p), h[1 - k], still(points_[fi][1 - k]), foot_up, options_);
      p.on = next_contact(p.on, h[k], v[k], landed, options_);
      p.before_last = p.last;
      p.last = now[k];
      on[k] = p.on;
    }
    out[fi] = {on[0], on[1]};
  }
  return out;
}

}  // namespace tonus::balance
