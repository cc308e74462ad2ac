// The robust balance filter (see robust_filter.hpp).
#include "tonus/host/balance/robust_filter.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>

#include "accel_operator.hpp"
#include "drop_envelope.hpp"
#include "tonus/host/balance/arm_swing.hpp"
#include "tonus/host/balance/zmp.hpp"
#include "zmp_partials.hpp"

namespace tonus::balance {
namespace {

using detail::AccelOperator;

// Per knot: the rotation vector (roll, pitch, yaw in the world), the shift
// (x, y) and each arm's swing (left, right).
constexpr std::size_t kDof = 7;
constexpr std::size_t kShift = 3, kArms = 5;  // the first component of each

// A uniform cubic B-spline over the analysed frames: frame kk (counted from
// the first analysed frame) is a blend of knots i0 .. i0 + 3.
struct Spline {
  double frames_per_knot = 1.0;
  std::size_t knots = 0;
  void basis(std::size_t kk, std::size_t& i0, std::array<double, 4>& w) const {
    const double u = static_cast<double>(kk) / frames_per_knot;
    const double fl = std::floor(u);
    const double f = u - fl;
    i0 = static_cast<std::size_t>(fl);
    w[0] = (1 - f) * (1 - f) * (1 - f) / 6.0;
    w[1] = (3 * f * f * f - 6 * f * f + 4) / 6.0;
    w[2] = (-3 * f * f * f + 3 * f * f + 3 * f + 1) / 6.0;
    w[3] = f * f * f / 6.0;
  }
};

// One layer of the correction: a spline over some of the five components.
struct Layer {
  Spline spline;
  std::vector<std::size_t> dofs;  // which components (0-2 rotation, 3-4 shift, 5-6 arms)
  Eigen::Index offset = 0;        // its first unknown
  std::array<double, kDof> weight{};
  double smoothness = 0.0;
  std::vector<bool> pinned;  // per knot: every frame it touches is airborne
  std::vector<double> far;   // per knot: its cost's multiplier, growing away from any imbalance
  [[nodiscard]] Eigen::Index column(std::size_t knot, std::size_t d) const {
    return offset + static_cast<Eigen::Index>(dofs.size() * knot + d);
  }
};

struct Member {
  AnalysisOptions options;
  AccelOperator op;
  std::size_t model = 0;  // which placement of the segments (Corrected::segments) it sees
  // Full form: each segment's axis acceleration in the original (D applied to
  // its axis series), from which a correction's change of the segments' own
  // angular momentum rate is taken.
  std::vector<std::array<Vec3, kSegmentParts>> axis_acc;  // [frame from the first analysed]
};

// D x for one segment quantity over the analysed frames (x: its series).
template <typename Get>
std::vector<std::array<Vec3, kSegmentParts>> apply_operator(const AccelOperator& op, std::size_t first, Get get) {
  std::vector<std::array<Vec3, kSegmentParts>> out(op.n);
  for (auto& f : out) f.fill(Vec3::Zero());
  for (std::size_t jj = 0; jj < op.n; ++jj) {
    const std::size_t lo = jj > op.band ? jj - op.band : 0, hi = std::min(op.n - 1, jj + op.band);
    for (std::size_t kk = lo; kk <= hi; ++kk) {
      const double w = op.at(kk, jj);
      if (w == 0.0) continue;
      for (std::size_t i = 0; i < kSegmentParts; ++i) out[kk][i] += w * get(first + jj, i);
    }
  }
  return out;
}

// The motion under one set of knots: each frame's correction, pose and segments.
struct Corrected {
  std::vector<Vec3> rotation;
  std::vector<Vec2> shift;
  std::vector<Vec2> arms;  // each arm's swing
  std::vector<MotionFrame> frames;
  std::vector<std::vector<SegmentFrame>> segments;  // [mass model][frame]
  std::vector<bool> changed;
  std::vector<bool> unreachable;
  std::vector<double> drop;  // per frame: the pelvis lowered, smoothed over time (drop_envelope.hpp)
  double max_drop_m = 0.0;
};

// Where each member's ZMP is under a correction, and how far outside.
struct Evaluation {
  Corrected motion;
  std::vector<std::vector<std::array<Vec3, kSegmentParts>>> acc;  // [member][frame]
  std::vector<std::vector<Vec2>> zmp;                             // [member][frame]
  std::vector<std::vector<double>> distance;                      // [member][frame]; -inf: not counted
  double cost = 0.0;
};

struct Problem {
  const HumanMotion& motion;
  const RobustFilterOptions& o;
  const std::vector<Member>& members;
  const std::vector<Analysis>& base;  // per member, the original
  std::vector<std::size_t> models;    // per mass model, a member that has it
  std::vector<Layer> layers;
  std::vector<std::array<double, 2>> follow;  // per frame and leg: how much a swinging foot follows the pelvis
  Eigen::SparseMatrix<double> regulariser;    // the correction's cost, q' R q
  detail::DropEnvelope drop_envelope;
};

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// A foot in the air follows the pelvis, fully once it is `ramp_s` from its
// lift-off and its touch-down and clear of the floor (a kick's foot; a
// walk's swing foot, a few centimetres up, mostly stays), easing in and out
// (smoothstep) so its path stays smooth; a foot down stays where the capture has it.
std::vector<std::array<double, 2>> follow_weights(const HumanMotion& motion, const ContactTrack& contacts,
                                                  double ramp_s) {
  constexpr double kClearFrom_m = 0.05, kClearOver_m = 0.10;
  const std::size_t n = contacts.frames.size(), first = motion.first_frame;
  const double dt = motion.dt_s;
  std::vector<std::array<double, 2>> w(n, std::array<double, 2>{});
  if (!(ramp_s > 0.0)) return w;
  for (std::size_t side = 0; side < 2; ++side) {
    std::vector<double> since(n, 1e9), until(n, 1e9);  // seconds since the last / until the next contact
    for (std::size_t t = first; t < n; ++t) {
      if (contacts.frames[t][side].any())
        since[t] = 0.0;
      else if (t > first)
        since[t] = since[t - 1] + dt;
    }
    for (std::size_t t = n; t-- > first;) {
      if (contacts.frames[t][side].any())
        until[t] = 0.0;
      else if (t + 1 < n)
        until[t] = until[t + 1] + dt;
    }
    const FootLandmarks fl = foot_landmarks(side == 0 ? Foot::left : Foot::right);
    for (std::size_t t = first; t < n; ++t) {
      const auto& p = motion.frames[t].p;
      const double clearance =
          std::min({p[index(fl.ankle)].z(), p[index(fl.toe_tip)].z(), p[index(fl.heel)].z()}) - contacts.ground_z_m;
      w[t][side] =
          smoothstep(std::min(since[t], until[t]) / ramp_s) * smoothstep((clearance - kClearFrom_m) / kClearOver_m);
    }
  }
  return w;
}

// A frame's correction under the knots q.
Eigen::Matrix<double, kDof, 1> frame_value(const Problem& p, const Eigen::VectorXd& q, std::size_t kk) {
  Eigen::Matrix<double, kDof, 1> v = Eigen::Matrix<double, kDof, 1>::Zero();
  for (const Layer& l : p.layers) {
    std::size_t i0 = 0;
    std::array<double, 4> w{};
    l.spline.basis(kk, i0, w);
    for (std::size_t b = 0; b < 4; ++b)
      for (std::size_t d = 0; d < l.dofs.size(); ++d)
        v(static_cast<Eigen::Index>(l.dofs[d])) += w[b] * q(l.column(i0 + b, d));
  }
  return v;
}

Corrected correct(const Problem& p, const Eigen::VectorXd& q) {
  const HumanMotion& m = p.motion;
  const std::size_t n = m.size(), first = m.first_frame;
  Corrected c;
  c.rotation.assign(n, Vec3::Zero());
  c.shift.assign(n, Vec2::Zero());
  c.arms.assign(n, Vec2::Zero());
  c.frames = m.frames;
  c.segments.resize(p.models.size());
  for (std::size_t k = 0; k < p.models.size(); ++k) c.segments[k] = p.base[p.models[k]].segments;
  c.changed.assign(n, false);
  c.unreachable.assign(n, false);
  // Each frame's turn and shift, and the drop its legs need; then the drop
  // eased over time, so the pelvis does not jolt where a leg straightens.
  std::vector<double> need(n, 0.0);
  for (std::size_t t = first; t < n; ++t) {
    const Eigen::Matrix<double, kDof, 1> v = frame_value(p, q, t - first);
    if (v.isZero(0.0)) continue;
    c.rotation[t] = v.head<3>();
    c.shift[t] = v.segment<2>(kShift);
    c.arms[t] = v.segment<2>(kArms);
    need[t] = std::max(waist_turn(m.frames[t], c.rotation[t], c.shift[t], p.follow[t]).drop_m, 0.0);
  }
  c.drop = p.drop_envelope.smooth(need);
  std::fill(c.drop.begin(), c.drop.begin() + static_cast<std::ptrdiff_t>(std::min(first, n)), 0.0);  // a T-pose stays
  for (std::size_t t = first; t < n; ++t) {
    if (c.rotation[t].isZero(0.0) && c.shift[t].isZero(0.0) && c.arms[t].isZero(0.0) && c.drop[t] == 0.0) continue;
    double drop = 0.0;
    bool reachable = true;
    c.frames[t] = swing_arms(
        correct_waist(m.frames[t], c.rotation[t], c.shift[t], &drop, &reachable, p.follow[t], c.drop[t]), c.arms[t]);
    c.drop[t] = drop;
    for (std::size_t k = 0; k < p.models.size(); ++k)
      c.segments[k][t] = place_segments(p.base[p.models[k]].mass, c.frames[t].p);
    c.changed[t] = true;
    c.unreachable[t] = !reachable;
    c.max_drop_m = std::max(c.max_drop_m, std::abs(drop));
  }
  return c;
}

// The direction in which the signed distance grows fastest at p (outward).
Vec2 distance_gradient(const ConvexPolygon& poly, const Vec2& p) {
  const std::size_t nv = poly.vertices.size();
  if (nv >= 3) {
    const Vec2 near = nearest_point(poly, p);
    if ((p - near).norm() > 1e-12) return (p - near).normalized();
    // Inside: the outward normal of the nearest edge (vertices counter-clockwise).
    double best = 1e300;
    Vec2 normal = Vec2::Zero();
    for (std::size_t i = 0; i < nv; ++i) {
      const Vec2 a = poly.vertices[i], e = poly.vertices[(i + 1) % nv] - a;
      if (e.norm() < 1e-12) continue;
      const Vec2 out(e.y() / e.norm(), -e.x() / e.norm());
      const double d = -(p - a).dot(out);  // distance inside, across this edge
      if (d < best) {
        best = d;
        normal = out;
      }
    }
    return normal;
  }
  const Vec2 near = nearest_point(poly, p);
  return (p - near).norm() > 1e-12 ? Vec2((p - near).normalized()) : Vec2::Zero();
}

// The correction's cost, q' R q: each knot's size and second difference, per
// frame it covers. Quadratic, so R is built once.
Eigen::SparseMatrix<double> regulariser_matrix(const std::vector<Layer>& layers, Eigen::Index unknowns) {
  std::vector<Eigen::Triplet<double>> reg;
  for (const Layer& l : layers) {
    const double fpk = l.spline.frames_per_knot;
    for (std::size_t i = 0; i < l.spline.knots; ++i) {
      for (std::size_t d = 0; d < l.dofs.size(); ++d) {
        const double w = l.weight[l.dofs[d]] * l.far[i];
        const auto c = static_cast<int>(l.column(i, d));
        reg.emplace_back(c, c, fpk * w * w);
        if (i == 0 || i + 1 >= l.spline.knots) continue;
        const double s2 = fpk * l.smoothness * l.smoothness * w * w;
        if (s2 == 0.0) continue;
        const auto stride = static_cast<int>(l.dofs.size());
        const int idx[3] = {c - stride, c, c + stride};
        const double coef[3] = {1.0, -2.0, 1.0};
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) reg.emplace_back(idx[a], idx[b], s2 * coef[a] * coef[b]);
      }
    }
  }
  Eigen::SparseMatrix<double> r(unknowns, unknowns);
  r.setFromTriplets(reg.begin(), reg.end());
  return r;
}

// out[k] += D[k, j] dx(j) over the changed frames j (clip frames; the
// operator's rows and columns count from `first`): a linear derivative of
// the original plus the operator applied to the change.
template <class Delta>
void add_operator_change(const AccelOperator& op, const std::vector<std::size_t>& changed, std::size_t first,
                         std::array<Vec3, kSegmentParts>* out, const Delta& delta) {
  for (const std::size_t j : changed) {
    const std::size_t jj = j - first;
    const std::size_t lo = jj > op.band ? jj - op.band : 0, hi = std::min(op.n - 1, jj + op.band);
    std::array<Vec3, kSegmentParts> dx;
    for (std::size_t i = 0; i < kSegmentParts; ++i) dx[i] = delta(j, i);
    for (std::size_t kk = lo; kk <= hi; ++kk) {
      const double w = op.at(kk, jj);
      if (w == 0.0) continue;
      for (std::size_t i = 0; i < kSegmentParts; ++i) out[kk][i] += w * dx[i];
    }
  }
}

Evaluation evaluate(const Problem& p, const Eigen::VectorXd& q) {
  Evaluation e;
  e.motion = correct(p, q);
  const HumanMotion& m = p.motion;
  const std::size_t n = m.size(), first = m.first_frame;
  const std::size_t count = p.members.size();
  e.acc.resize(count);
  e.zmp.resize(count);
  e.distance.resize(count);
  std::vector<std::size_t> changed;
  for (std::size_t t = first; t < n; ++t)
    if (e.motion.changed[t]) changed.push_back(t);
  for (std::size_t mi = 0; mi < count; ++mi) {
    const Analysis& a = p.base[mi];
    const AccelOperator& op = p.members[mi].op;
    const std::vector<SegmentFrame>& segments = e.motion.segments[p.members[mi].model];
    auto& acc = e.acc[mi];
    acc = a.accelerations;
    // a(x + dx) = a(x) + D dx: only the changed frames contribute.
    add_operator_change(op, changed, first, acc.data() + first,
                        [&](std::size_t j, std::size_t i) { return Vec3(segments[j][i].com - a.segments[j][i].com); });
    // Full form: the segments' own angular momentum rate, m rg^2 axis x axis'',
    // changes with their axes; the original's rate plus that change.
    std::vector<Vec3> rate;
    const Member& mem = p.members[mi];
    if (!mem.axis_acc.empty()) {
      rate = a.angular_momentum_rate;
      std::vector<std::array<Vec3, kSegmentParts>> axis_acc = mem.axis_acc;
      add_operator_change(op, changed, first, axis_acc.data(), [&](std::size_t j, std::size_t i) {
        return Vec3(segments[j][i].axis - a.segments[j][i].axis);
      });
      for (std::size_t t = first; t < n; ++t) {
        for (std::size_t i = 0; i < kSegmentParts; ++i) {
          rate[t] += segment_angular_momentum(a.mass, i, segments[t][i], axis_acc[t - first][i]) -
                     segment_angular_momentum(a.mass, i, a.segments[t][i], mem.axis_acc[t - first][i]);
        }
      }
    }
    e.zmp[mi].assign(n, Vec2::Zero());
    e.distance[mi].assign(n, -1e300);
    for (std::size_t t = first; t < n; ++t) {
      const FrameAnalysis& f = a.frames[t];
      if (!f.analysed || f.airborne) continue;
      ZmpInputs in;
      in.segments = &segments[t];
      in.accel = &acc[t];
      in.angular_momentum_rate = rate.empty() ? a.angular_momentum_rate[t] : rate[t];
      const ZmpResult z = zero_moment_point(a.mass, in, a.contacts.ground_z_m, p.members[mi].options.gravity);
      if (!z.defined) continue;
      e.zmp[mi][t] = z.zmp;
      const double d = signed_distance(f.support, z.zmp);
      e.distance[mi][t] = d;
      const double h = d + p.o.margin_m;
      if (h > 0.0) e.cost += h * h;
    }
  }
  e.cost += q.dot(p.regulariser * q);
  for (std::size_t t = first; t < n; ++t)
    e.cost += e.motion.unreachable[t] && !p.base.front().frames[t].airborne ? 1.0 : 0.0;
  return e;
}

std::size_t worst_outside(const Evaluation& e, double threshold) {
  std::size_t worst = 0;
  for (const auto& d : e.distance) {
    std::size_t k = 0;
    for (const double v : d) k += v > threshold ? 1U : 0U;
    worst = std::max(worst, k);
  }
  return worst;
}

// Caps per knot: a blend of capped knots is capped. The fine layer's shift has its own cap.
void clamp_knots(const RobustFilterOptions& o, const std::vector<Layer>& layers, Eigen::VectorXd& q) {
  for (const Layer& l : layers) {
    const bool fine = l.dofs.size() == 2;
    for (std::size_t i = 0; i < l.spline.knots; ++i) {
      auto v = q.segment(l.column(i, 0), static_cast<Eigen::Index>(l.dofs.size()));
      if (l.pinned[i]) {
        v.setZero();
        continue;
      }
      const Eigen::Index s0 = fine ? 0 : static_cast<Eigen::Index>(kShift);
      if (!fine) {
        const double lean = v.head<2>().norm();
        if (lean > o.max_lean_rad) v.head<2>() *= o.max_lean_rad / lean;
        v(2) = std::clamp(v(2), -o.max_yaw_rad, o.max_yaw_rad);
        for (std::size_t d = kArms; d < l.dofs.size(); ++d) {  // the arms, when they are unknowns
          const auto c = static_cast<Eigen::Index>(d);
          v(c) = std::clamp(v(c), -o.max_arm_swing_rad, o.max_arm_swing_rad);
        }
      }
      const double cap = fine ? o.max_fine_shift_m : o.max_shift_m;
      const double sn = v.segment<2>(s0).norm();
      if (sn > cap) v.segment<2>(s0) *= cap / sn;
    }
  }
}

}  // namespace

RobustFilterResult robust_balance_filter(const HumanMotion& motion, const RobustFilterOptions& o,
                                         FilterProgress progress, void* user) {
  RobustFilterResult r;
  const std::size_t n = motion.size(), first = motion.first_frame;
  const auto finite_not_negative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!(std::isfinite(o.knot_spacing_s) && o.knot_spacing_s > 0.0) || !finite_not_negative(o.margin_m) ||
      !finite_not_negative(o.max_lean_rad) || !finite_not_negative(o.max_yaw_rad) ||
      !finite_not_negative(o.max_shift_m) || !finite_not_negative(o.max_arm_swing_rad) ||
      !finite_not_negative(o.arm_weight) || !finite_not_negative(o.lean_weight) || !finite_not_negative(o.yaw_weight) ||
      !finite_not_negative(o.shift_weight) || !finite_not_negative(o.smoothness) ||
      !finite_not_negative(o.fine_knot_spacing_s) || !finite_not_negative(o.max_fine_shift_m) ||
      !finite_not_negative(o.fine_shift_weight) || !finite_not_negative(o.swing_follow_ramp_s) ||
      !(std::isfinite(o.far_weight) && o.far_weight >= 1.0) || !finite_not_negative(o.local_reach_s) ||
      o.max_iterations < 0) {
    r.error =
        "robust filter: the knot spacing must be positive, and the margin, limits and weights finite and not "
        "negative";
    return r;
  }
  const Analysis detected = analyse(motion, o.analysis);
  if (!detected.ok()) {
    r.error = detected.error;
    return r;
  }
  const ContactTrack& contacts = detected.contacts;  // the feet do not move: neither do their contacts
  r.members = estimator_family(o.analysis, o.both_trunks);
  r.before = analyse_family(motion, r.members, contacts);
  for (const Analysis& a : r.before) {
    if (!a.ok()) {
      r.error = a.error;
      return r;
    }
  }
  r.verdict_before = family_verdict(r.before, r.members);
  const std::size_t m = n - first;
  std::vector<Member> members;
  std::vector<std::size_t> models;  // per trunk model met, its first member
  for (const AnalysisOptions& mo : r.members) {
    std::size_t model = 0;
    while (model < models.size() && r.members[models[model]].trunk != mo.trunk) ++model;
    if (model == models.size()) models.push_back(members.size());
    members.push_back({mo, detail::accel_operator(m, motion.dt_s, mo.derivatives), model, {}});
    if (mo.angular_momentum) {
      const Analysis& base = r.before[members.size() - 1];
      members.back().axis_acc = apply_operator(members.back().op, first,
                                               [&](std::size_t t, std::size_t i) { return base.segments[t][i].axis; });
    }
    r.lookahead_frames = std::max(r.lookahead_frames, members.back().op.band);
  }

  Problem p{motion,
            o,
            members,
            r.before,
            models,
            {},
            follow_weights(motion, contacts, o.swing_follow_ramp_s),
            {},
            detail::DropEnvelope(motion.dt_s)};
  // The balance layer (lean, yaw, shift) and the fine layer (a few millimetres
  // of shift, fast enough to take the capture's jitter out of the centre of mass).
  std::vector<std::size_t> imbalanced;  // frames (from the first analysed) outside under some member
  for (std::size_t kk = 0; kk < m; ++kk) {
    for (const Analysis& a : r.before) {
      const FrameAnalysis& f = a.frames[first + kk];
      if (f.analysed && !f.airborne && f.zmp_defined && f.outside_m > 0.0) {
        imbalanced.push_back(kk);
        break;
      }
    }
  }
  Eigen::Index unknowns = 0;
  for (const bool fine : {false, true}) {
    if (fine && !(o.fine_knot_spacing_s > 0.0 && o.max_fine_shift_m > 0.0)) continue;
    Layer l;
    l.spline.frames_per_knot = std::max(1.0, (fine ? o.fine_knot_spacing_s : o.knot_spacing_s) / motion.dt_s);
    l.spline.knots = static_cast<std::size_t>(std::floor(static_cast<double>(m - 1) / l.spline.frames_per_knot)) + 4;
    // A zero cap leaves the arms out of the unknowns altogether.
    l.dofs =
        fine ? std::vector<std::size_t>{kShift, kShift + 1} : std::vector<std::size_t>{0, 1, 2, kShift, kShift + 1};
    if (!fine && o.max_arm_swing_rad > 0.0) l.dofs.insert(l.dofs.end(), {kArms, kArms + 1});
    l.offset = unknowns;
    l.weight = {o.lean_weight,
                o.lean_weight,
                o.yaw_weight,
                fine ? o.fine_shift_weight : o.shift_weight,
                fine ? o.fine_shift_weight : o.shift_weight,
                o.arm_weight,
                o.arm_weight};
    l.smoothness = fine ? 0.0 : o.smoothness;
    l.pinned.assign(l.spline.knots, true);
    for (std::size_t kk = 0; kk < m; ++kk) {
      if (r.before.front().frames[first + kk].airborne) continue;
      std::size_t i0 = 0;
      std::array<double, 4> w{};
      l.spline.basis(kk, i0, w);
      for (std::size_t b = 0; b < 4; ++b) l.pinned[i0 + b] = false;
    }
    // Locality: a knot whose peak is far (in time) from every frame that is
    // outside under some member costs more, so a correction stays near the
    // imbalance it answers instead of spreading along the clip.
    l.far.assign(l.spline.knots, 1.0);
    for (std::size_t i = 0; i < l.spline.knots; ++i) {
      const double peak = (static_cast<double>(i) - 1.0) * l.spline.frames_per_knot;
      double nearest = 1e9;
      for (const std::size_t kk : imbalanced) nearest = std::min(nearest, std::abs(static_cast<double>(kk) - peak));
      l.far[i] = 1.0 + (o.far_weight - 1.0) * smoothstep((nearest * motion.dt_s - o.local_reach_s) / o.local_reach_s);
    }
    if (!fine) r.lookahead_frames += static_cast<std::size_t>(std::ceil(2.0 * l.spline.frames_per_knot));
    unknowns += static_cast<Eigen::Index>(l.dofs.size() * l.spline.knots);
    p.layers.push_back(std::move(l));
  }
  p.regulariser = regulariser_matrix(p.layers, unknowns);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(unknowns);
  // The components probed: the balance layer's (the first), which lists them in order.
  const std::size_t dofs = p.layers.front().dofs.size();
  Evaluation now = evaluate(p, q);
  double damping = 1e-4;
  const double h = 1e-6;
  for (r.iterations = 0; r.iterations < o.max_iterations; ++r.iterations) {
    if (progress != nullptr) progress(r.iterations, worst_outside(now, kFamilyThreshold_m), user);
    // Each frame's segments under a small change of each of its correction's components.
    using FrameDerivative = std::vector<std::array<std::array<Vec3, kSegmentParts>, kDof>>;  // [frame][dof][part]
    std::vector<FrameDerivative> dcom(models.size(), FrameDerivative(n)), daxis(models.size(), FrameDerivative(n));
    std::vector<bool> needed(n, false);
    for (std::size_t mi = 0; mi < members.size(); ++mi) {
      for (std::size_t t = first; t < n; ++t) {
        if (now.distance[mi][t] + o.margin_m <= 0.0) continue;
        const std::size_t kk = t - first, band = members[mi].op.band;
        for (std::size_t jj = kk > band ? kk - band : 0; jj <= std::min(m - 1, kk + band); ++jj)
          needed[first + jj] = true;
      }
    }
    bool any = false;
    for (std::size_t t = first; t < n; ++t) {
      if (!needed[t]) continue;
      any = true;
      for (std::size_t e = 0; e < dofs; ++e) {
        Vec3 rot = now.motion.rotation[t];
        Vec2 sh = now.motion.shift[t], arms = now.motion.arms[t];
        if (e < kShift)
          rot(static_cast<Eigen::Index>(e)) += h;
        else if (e < kArms)
          sh(static_cast<Eigen::Index>(e - kShift)) += h;
        else
          arms(static_cast<Eigen::Index>(e - kArms)) += h;
        const MotionFrame probe = swing_arms(
            correct_waist(motion.frames[t], rot, sh, nullptr, nullptr, p.follow[t], now.motion.drop[t]), arms);
        for (std::size_t k = 0; k < models.size(); ++k) {
          const SegmentFrame moved = place_segments(r.before[models[k]].mass, probe.p);
          const SegmentFrame& at = now.motion.segments[k][t];
          for (std::size_t i = 0; i < kSegmentParts; ++i) dcom[k][t][e][i] = (moved[i].com - at[i].com) / h;
          for (std::size_t i = 0; i < kSegmentParts; ++i) daxis[k][t][e][i] = (moved[i].axis - at[i].axis) / h;
        }
      }
    }
    if (!any) break;  // no frame near an edge under any member: nothing to correct

    // Rows: each member's violation at each frame near or past the edge.
    using Triplet = Eigen::Triplet<double>;
    std::vector<Triplet> jac;
    std::vector<double> residual;
    Eigen::VectorXd local = Eigen::VectorXd::Zero(unknowns);
    std::vector<Eigen::Index> touched;
    for (std::size_t mi = 0; mi < members.size(); ++mi) {
      const Analysis& a = r.before[mi];
      const AccelOperator& op = members[mi].op;
      const std::size_t model = members[mi].model;
      const std::vector<SegmentFrame>& segments = now.motion.segments[model];
      for (std::size_t t = first; t < n; ++t) {
        const double viol = now.distance[mi][t] + o.margin_m;
        if (viol <= 0.0) continue;
        const Vec2 normal = distance_gradient(a.frames[t].support, now.zmp[mi][t]);
        const detail::ZmpPartials dp = detail::zmp_partials(a.mass, segments[t], now.acc[mi][t], now.zmp[mi][t],
                                                            a.contacts.ground_z_m, members[mi].options.gravity);
        std::array<Eigen::RowVector3d, kSegmentParts> along_pos, along_acc;
        for (std::size_t i = 0; i < kSegmentParts; ++i) {
          along_pos[i] = normal.transpose() * dp.dpos[i];
          along_acc[i] = normal.transpose() * dp.dacc[i];
        }
        // Full form: the ZMP moves by (rate_x n_y - rate_y n_x) / N with the
        // segments' own angular momentum rate, m rg^2 axis x axis''.
        const bool full = !members[mi].axis_acc.empty();
        std::array<Eigen::RowVector3d, kSegmentParts> along_axis_acc;
        if (full) {
          double big_n = 0.0;
          for (std::size_t i = 0; i < kSegmentParts; ++i)
            big_n += a.mass.parts[i].mass_kg * (now.acc[mi][t][i].z() + members[mi].options.gravity);
          const Vec3 r_vec = Vec3(normal.y(), -normal.x(), 0.0) / big_n;
          for (std::size_t i = 0; i < kSegmentParts; ++i)
            for (Eigen::Index c = 0; c < 3; ++c)
              along_axis_acc[i](c) = r_vec.dot(segment_angular_momentum(a.mass, i, segments[t][i], Vec3::Unit(c)));
        }
        const std::size_t kk = t - first;
        const std::size_t lo = kk > op.band ? kk - op.band : 0, hi = std::min(m - 1, kk + op.band);
        touched.clear();
        for (std::size_t jj = lo; jj <= hi; ++jj) {
          const double w = op.at(kk, jj);
          if (w == 0.0 && jj != kk) continue;
          std::array<double, kDof> g{};
          for (std::size_t e = 0; e < dofs; ++e) {
            for (std::size_t i = 0; i < kSegmentParts; ++i) {
              const Vec3& dc = dcom[model][first + jj][e][i];
              g[e] += w * along_acc[i].dot(dc);
              if (jj == kk) g[e] += along_pos[i].dot(dc);
              if (full) g[e] += w * along_axis_acc[i].dot(daxis[model][first + jj][e][i]);
            }
          }
          for (const Layer& l : p.layers) {
            std::size_t i0 = 0;
            std::array<double, 4> bw{};
            l.spline.basis(jj, i0, bw);
            for (std::size_t b = 0; b < 4; ++b) {
              if (l.pinned[i0 + b]) continue;
              for (std::size_t d = 0; d < l.dofs.size(); ++d) {
                const Eigen::Index col = l.column(i0 + b, d);
                if (local(col) == 0.0) touched.push_back(col);
                local(col) += g[l.dofs[d]] * bw[b];
              }
            }
          }
        }
        const auto row = static_cast<int>(residual.size());
        for (const Eigen::Index col : touched) {
          if (local(col) != 0.0) jac.emplace_back(row, static_cast<int>(col), local(col));
          local(col) = 0.0;
        }
        residual.push_back(viol);
      }
    }
    Eigen::SparseMatrix<double> j_mat(static_cast<Eigen::Index>(residual.size()), unknowns);
    j_mat.setFromTriplets(jac.begin(), jac.end());
    Eigen::SparseMatrix<double> hess = j_mat.transpose() * j_mat;
    Eigen::VectorXd grad = j_mat.transpose() * Eigen::Map<const Eigen::VectorXd>(
                                                   residual.data(), static_cast<Eigen::Index>(residual.size()));
    // The regulariser's exact Hessian and gradient (it is quadratic).
    hess += p.regulariser;
    grad += p.regulariser * q;
    for (const Layer& l : p.layers) {
      for (std::size_t i = 0; i < l.spline.knots; ++i) {
        if (!l.pinned[i]) continue;
        for (std::size_t d = 0; d < l.dofs.size(); ++d) grad(l.column(i, d)) = 0.0;
      }
    }

    bool accepted = false;
    double improvement = 0.0;
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      Eigen::SparseMatrix<double> damped = hess;
      for (Eigen::Index i = 0; i < unknowns; ++i) damped.coeffRef(i, i) += damping * (1.0 + hess.coeff(i, i));
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(damped);
      if (solver.info() != Eigen::Success) {
        damping *= 10.0;
        continue;
      }
      Eigen::VectorXd trial = q - solver.solve(grad);
      clamp_knots(o, p.layers, trial);
      Evaluation cand = evaluate(p, trial);
      if (cand.cost < now.cost) {
        improvement = (now.cost - cand.cost) / std::max(now.cost, 1e-300);
        q = std::move(trial);
        now = std::move(cand);
        accepted = true;
        damping = std::max(damping / 3.0, 1e-9);
      } else {
        damping *= 10.0;
      }
    }
    if (!accepted || improvement < 1e-5) break;  // as good as it gets
  }

  // The result, analysed afresh (smoothing included) under every member.
  r.follow = p.follow;
  r.drop_m = now.motion.drop;
  r.rotation = now.motion.rotation;
  r.shift_m = now.motion.shift;
  r.arm_swing_rad = now.motion.arms;
  r.corrected = motion;
  r.corrected.frames = now.motion.frames;
  r.max_drop_m = now.motion.max_drop_m;
  r.after = analyse_family(r.corrected, r.members, contacts);
  for (const Analysis& a : r.after) {
    if (!a.ok()) {
      r.error = "analysing the corrected motion: " + a.error;
      return r;
    }
  }
  r.verdict_after = family_verdict(r.after, r.members);
  r.unsolved.assign(n, false);
  for (std::size_t t = first; t < n; ++t) {
    for (const Analysis& a : r.after) {
      const FrameAnalysis& f = a.frames[t];
      if (f.analysed && !f.airborne && f.zmp_defined && f.outside_m > kFamilyThreshold_m) r.unsolved[t] = true;
    }
    r.frames_unsolved += r.unsolved[t] ? 1U : 0U;
    r.frames_unreachable += now.motion.unreachable[t] ? 1U : 0U;
    r.max_lean_rad = std::max(r.max_lean_rad, r.rotation[t].head<2>().norm());
    r.max_yaw_rad = std::max(r.max_yaw_rad, std::abs(r.rotation[t].z()));
    r.max_shift_m = std::max(r.max_shift_m, r.shift_m[t].norm());
    r.max_arm_swing_rad = std::max(r.max_arm_swing_rad, r.arm_swing_rad[t].cwiseAbs().maxCoeff());
    for (const Foot foot : {Foot::left, Foot::right}) {
      const FootLandmarks fl = foot_landmarks(foot);
      double& largest =
          p.follow[t][foot == Foot::left ? 0 : 1] > 0.0 ? r.max_swing_foot_displacement_m : r.max_foot_displacement_m;
      for (const Landmark l : {fl.ankle, fl.toe_joint, fl.toe_tip, fl.heel})
        largest = std::max(largest, (r.corrected.frames[t].p[index(l)] - motion.frames[t].p[index(l)]).norm());
    }
  }
  return r;
}

}  // namespace tonus::balance
