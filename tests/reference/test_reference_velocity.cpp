// ReferenceVelocity against closed forms: a hinge a sin(w t), a ball joint
// about a fixed body axis and about a turning axis, the root translating and
// yawing on a tilted body. Each velocity and acceleration is compared with the
// analytic derivative at the delayed sample (out.index), after the start
// transient. Then what the stream must survive: quaternion sign flips, missing
// (NaN, garbage) frames, a reset.
//
// Tolerances, from how the fixed-lag smoother treats a sine at f (measured
// with derivatives::FixedLag alone on sin(2 pi f t)): the causal filter (lag 0)
// is off by about 10 (f/fc)^3 of the peak velocity; the backward pass removes
// that as the lag grows, with an oscillating envelope near e^(-pi fc lag_s),
// down to the interior smoother's (f/fc)^6. For 1 Hz: 1.3e-3 at 120 Hz, fc 6,
// lag 20 (1/6 s) and 3.3e-3 at 1 kHz, fc 8, lag 60 (the avatar's), which is
// what the hinge here measures. The motions keep their content at or below
// 1.8 Hz; each bound is about twice the largest figure measured over the
// groups (acceleration: the same law, one power of f more), printed by the
// test and listed in host/reference/README.md.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "tonus/host/reference/reference_velocity.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/math.hpp"

using namespace tonus;
using reference::ReferenceVelocity;
using sim::Quat;
using sim::Vec3;

namespace {

constexpr double kPi = std::numbers::pi;

// Index a + k of a qpos or qvel array.
std::size_t slot(int a, int k) { return static_cast<std::size_t>(a) + static_cast<std::size_t>(k); }

const sim::Model& humanoid() {
  static const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  return *built.model;
}

const sim::Body& body(const sim::Model& m, const char* name) {
  const int i = m.body_index(name);
  REQUIRE(i >= 0);
  return m.bodies[static_cast<std::size_t>(i)];
}

void put_quat(std::array<double, sim::kMaxQpos>& q, int a, const Quat& r) {
  const auto k = static_cast<std::size_t>(a);
  q[k] = r.w();
  q[k + 1] = r.x();
  q[k + 2] = r.y();
  q[k + 3] = r.z();
}

Quat quat_of(const std::array<double, sim::kMaxQpos>& q, int a) {
  const auto k = static_cast<std::size_t>(a);
  return {q[k], q[k + 1], q[k + 2], q[k + 3]};
}

Quat axis_angle(double angle, const Vec3& axis) { return Quat(Eigen::AngleAxisd(angle, axis.normalized())); }

// The closed-form motion: qpos, qvel and qacc at time t.
struct Truth {
  std::array<double, sim::kMaxQpos> qpos{};
  std::array<double, sim::kMaxDofs> qvel{};
  std::array<double, sim::kMaxDofs> qacc{};
};

constexpr double kTilt = 0.2;  // the root's constant tilt about its x axis, under the yaw

struct Motion {
  const sim::Body* elbow = nullptr;     // hinge: a sin(w t)
  const sim::Body* shoulder = nullptr;  // ball, fixed body axis, constant rate
  const sim::Body* hip = nullptr;       // ball, turning axis: Rz(alpha(t)) Rx(beta(t))
  const sim::Body* root = nullptr;

  explicit Motion(const sim::Model& m)
      : elbow(&body(m, "LeftLowerArm")),
        shoulder(&body(m, "RightUpperArm")),
        hip(&body(m, "LeftUpperLeg")),
        root(&m.bodies[0]) {
    REQUIRE(elbow->joint == sim::JointType::hinge);
    REQUIRE(shoulder->joint == sim::JointType::ball);
    REQUIRE(hip->joint == sim::JointType::ball);
    REQUIRE(root->joint == sim::JointType::free);
  }

  [[nodiscard]] Truth at(const sim::Model& m, double t) const {
    Truth r;
    r.qpos = m.qpos0;
    // Hinge: 0.5 sin(2 pi 1.0 t).
    {
      const double a = 0.5, w = 2 * kPi * 1.0;
      r.qpos[static_cast<std::size_t>(elbow->qpos_adr)] = 0.8 + a * std::sin(w * t);
      r.qvel[static_cast<std::size_t>(elbow->dof_adr)] = a * w * std::cos(w * t);
      r.qacc[static_cast<std::size_t>(elbow->dof_adr)] = -a * w * w * std::sin(w * t);
    }
    // Ball about a fixed body axis n at 2 rad/s: body angular velocity n * 2, no acceleration.
    {
      const Vec3 n = Vec3(0.3, -0.5, 0.8).normalized();
      const double rate = 2.0;
      put_quat(r.qpos, shoulder->qpos_adr, axis_angle(0.4, Vec3::UnitY()) * axis_angle(rate * t, n));
      for (int k = 0; k < 3; ++k) r.qvel[slot(shoulder->dof_adr, k)] = rate * n(k);
    }
    // Ball on a turning axis: q = Rz(alpha) Rx(beta); body angular velocity
    // (beta', alpha' sin beta, alpha' cos beta) and its derivative.
    {
      const double wa = 2 * kPi * 0.5, wb = 2 * kPi * 0.7;
      const double al = 0.8 * std::sin(wa * t), al1 = 0.8 * wa * std::cos(wa * t),
                   al2 = -0.8 * wa * wa * std::sin(wa * t);
      const double be = 0.6 * std::sin(wb * t + 0.3), be1 = 0.6 * wb * std::cos(wb * t + 0.3),
                   be2 = -0.6 * wb * wb * std::sin(wb * t + 0.3);
      put_quat(r.qpos, hip->qpos_adr, axis_angle(al, Vec3::UnitZ()) * axis_angle(be, Vec3::UnitX()));
      const auto d = static_cast<std::size_t>(hip->dof_adr);
      const double s = std::sin(be), c = std::cos(be);
      r.qvel[d] = be1;
      r.qvel[d + 1] = al1 * s;
      r.qvel[d + 2] = al1 * c;
      r.qacc[d] = be2;
      r.qacc[d + 1] = al2 * s + al1 * be1 * c;
      r.qacc[d + 2] = al2 * c - al1 * be1 * s;
    }
    // Root: walking along x at 1.2 m/s, swaying in y, yaw 0.5 t + 0.3 sin(2 pi 0.8 t)
    // about world z over a constant tilt: body angular velocity (0, sin tilt, cos tilt) yaw'.
    {
      const double ws = 2 * kPi * 0.9, wy = 2 * kPi * 0.8;
      const double yaw = 0.5 * t + 0.3 * std::sin(wy * t), yaw1 = 0.5 + 0.3 * wy * std::cos(wy * t),
                   yaw2 = -0.3 * wy * wy * std::sin(wy * t);
      const std::array<double, 3> p{1.2 * t, 0.05 * std::sin(ws * t), 0.9 + 0.02 * std::cos(2 * ws * t)};
      const std::array<double, 3> v{1.2, 0.05 * ws * std::cos(ws * t), -0.04 * ws * std::sin(2 * ws * t)};
      const std::array<double, 3> acc{0.0, -0.05 * ws * ws * std::sin(ws * t), -0.08 * ws * ws * std::cos(2 * ws * t)};
      const auto a = static_cast<std::size_t>(root->qpos_adr);
      const auto d = static_cast<std::size_t>(root->dof_adr);
      for (std::size_t k = 0; k < 3; ++k) {
        r.qpos[a + k] = p[k];
        r.qvel[d + k] = v[k];
        r.qacc[d + k] = acc[k];
      }
      put_quat(r.qpos, root->qpos_adr + 3, axis_angle(yaw, Vec3::UnitZ()) * axis_angle(kTilt, Vec3::UnitX()));
      r.qvel[d + 4] = std::sin(kTilt) * yaw1;
      r.qvel[d + 5] = std::cos(kTilt) * yaw1;
      r.qacc[d + 4] = std::sin(kTilt) * yaw2;
      r.qacc[d + 5] = std::cos(kTilt) * yaw2;
    }
    return r;
  }
};

struct Setting {
  double dt_s;
  double cutoff_hz;
  int lag;
  double vel_rel;  // bound on the velocity error, relative to the peak (about twice the measured)
  double acc_rel;  // ... acceleration
};
// Mocap at 120 Hz with the derivatives' default cutoff and 1/6 s of lag, and
// the avatar's own tick (1 kHz, fc 8 Hz, 60 ticks).
constexpr std::array<Setting, 2> kSettings{{{1.0 / 120.0, 6.0, 20, 3e-3, 1.2e-2}, {1e-3, 8.0, 60, 7e-3, 4e-2}}};

struct GroupErrors {
  double qpos_abs = 0.0;  // delayed qpos against the truth at out.index (exact: a copy)
  int checked = 0;
};

double max_abs(std::span<const double> x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

}  // namespace

TEST_CASE("reference velocity: create refuses a bad lag or cutoff") {
  const sim::Model& m = humanoid();
  CHECK_FALSE(ReferenceVelocity::create(m, 1e-3, 8.0, -1));
  CHECK_FALSE(ReferenceVelocity::create(m, 1e-3, 8.0, 121));
  CHECK_FALSE(ReferenceVelocity::create(m, 1e-3, -1.0, 10));
  CHECK_FALSE(ReferenceVelocity::create(m, 0.0, 8.0, 10));
  CHECK_FALSE(ReferenceVelocity::create(m, 1e-3, std::numeric_limits<double>::quiet_NaN(), 10));
  const ReferenceVelocity::Created ok = ReferenceVelocity::create(m, 1e-3, 8.0, 0);
  REQUIRE_MESSAGE(ok, ok.error);
  CHECK(ok.velocity->delay_s() == 0.0);
}

TEST_CASE("reference velocity: closed forms (hinge, fixed and turning ball axes, root walking and yawing)") {
  const sim::Model& m = humanoid();
  const Motion motion(m);
  for (const Setting& s : kSettings) {
    CAPTURE(s.dt_s);
    ReferenceVelocity::Created made = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
    REQUIRE_MESSAGE(made, made.error);
    ReferenceVelocity& rv = *made.velocity;
    CHECK(rv.delay_s() == doctest::Approx(s.lag * s.dt_s));
    const int frames = static_cast<int>(std::lround(6.0 / s.dt_s));
    const double settle_s = 1.0;  // the start transient (a stream starting mid-motion), docs/derivatives.md
    GroupErrors ge;
    std::array<double, 5> vel_peak{}, acc_peak{};
    std::array<double, 5> vel_err{}, acc_err{};
    ReferenceVelocity::Output out;
    for (int k = 0; k < frames; ++k) {
      const Truth in = motion.at(m, k * s.dt_s);
      const bool warm = rv.push(std::span<const double>(in.qpos.data(), static_cast<std::size_t>(m.nq)), out);
      CHECK(warm == (k >= s.lag));
      CHECK(out.index == static_cast<std::size_t>(std::max(0, k - s.lag)));
      CHECK(out.missing_joints == 0);
      const double t = static_cast<double>(out.index) * s.dt_s;
      const Truth tr = motion.at(m, t);
      if (!warm) {
        CHECK(max_abs(out.qvel) == 0.0);
        continue;
      }
      for (int q = 0; q < m.nq; ++q) {
        ge.qpos_abs = std::max(ge.qpos_abs,
                               std::abs(out.qpos[static_cast<std::size_t>(q)] - tr.qpos[static_cast<std::size_t>(q)]));
      }
      if (t < settle_s) continue;
      ++ge.checked;
      // Groups: hinge, fixed axis, turning axis, root linear, root angular.
      const std::array<std::pair<int, int>, 5> groups{
          {{motion.elbow->dof_adr, 1}, {motion.shoulder->dof_adr, 3}, {motion.hip->dof_adr, 3}, {0, 3}, {3, 3}}};
      for (std::size_t g = 0; g < groups.size(); ++g) {
        for (int c = 0; c < groups[g].second; ++c) {
          const auto d = slot(groups[g].first, c);
          vel_peak[g] = std::max(vel_peak[g], std::abs(tr.qvel[d]));
          acc_peak[g] = std::max(acc_peak[g], std::abs(tr.qacc[d]));
          vel_err[g] = std::max(vel_err[g], std::abs(out.qvel[d] - tr.qvel[d]));
          acc_err[g] = std::max(acc_err[g], std::abs(out.qacc[d] - tr.qacc[d]));
        }
      }
      // Every other dof at rest.
      for (int b = 1; b < m.nbody; ++b) {
        const sim::Body& bb = m.bodies[static_cast<std::size_t>(b)];
        if (&bb == motion.elbow || &bb == motion.shoulder || &bb == motion.hip) continue;
        for (int c = 0; c < bb.dof_num; ++c) {
          CHECK(std::abs(out.qvel[slot(bb.dof_adr, c)]) < 1e-12);
          CHECK(std::abs(out.qacc[slot(bb.dof_adr, c)]) < 1e-12);
        }
      }
    }
    REQUIRE(ge.checked > 100);
    const std::array<const char*, 5> names{"hinge", "ball, fixed axis", "ball, turning axis", "root linear",
                                           "root angular"};
    for (std::size_t g = 0; g < 5; ++g) {
      const double vr = vel_err[g] / vel_peak[g];
      const double ar = acc_peak[g] > 0.0 ? acc_err[g] / acc_peak[g] : 0.0;
      MESSAGE("dt " << s.dt_s << " fc " << s.cutoff_hz << " lag " << s.lag << ": " << std::string(names[g])
                    << ": vel max err " << vel_err[g] << " (" << 100 * vr << " % of " << vel_peak[g]
                    << "), acc max err " << acc_err[g] << " (" << 100 * ar << " % of " << acc_peak[g] << ")");
      if (g == 1) {
        // Constant rate about a fixed body axis: the running coordinate is a
        // line, which the constant-acceleration smoother reproduces exactly.
        CHECK(vel_err[g] < 1e-9);
        CHECK(acc_err[g] < 1e-7);
        continue;
      }
      CHECK(vr < s.vel_rel);  // the lag's truncation: see the top
      CHECK(ar < s.acc_rel);
    }
    MESSAGE("delayed qpos against the truth at its index: " << ge.qpos_abs);
    CHECK(ge.qpos_abs < 1e-14);  // the input itself, delayed
  }
}

TEST_CASE("reference velocity: a quaternion whose sign flips every other frame changes nothing") {
  const sim::Model& m = humanoid();
  const Motion motion(m);
  const Setting s = kSettings[0];
  ReferenceVelocity::Created a = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
  ReferenceVelocity::Created b = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
  REQUIRE(a);
  REQUIRE(b);
  ReferenceVelocity::Output oa, ob;
  double vel_diff = 0.0, acc_diff = 0.0, qpos_diff = 0.0, min_dot = 1.0;
  Quat prev_root = Quat::Identity(), prev_hip = Quat::Identity();
  for (int k = 0; k < 600; ++k) {
    Truth in = motion.at(m, k * s.dt_s);
    a.velocity->push(in.qpos, oa);
    if (k % 2 == 1) {
      for (const sim::Body* bb : {motion.shoulder, motion.hip}) {
        for (int c = 0; c < 4; ++c) in.qpos[slot(bb->qpos_adr, c)] *= -1.0;
      }
      for (int c = 3; c < 7; ++c) in.qpos[static_cast<std::size_t>(c)] *= -1.0;
    }
    b.velocity->push(in.qpos, ob);
    for (std::size_t d = 0; d < static_cast<std::size_t>(m.nv); ++d) {
      vel_diff = std::max(vel_diff, std::abs(oa.qvel[d] - ob.qvel[d]));
      acc_diff = std::max(acc_diff, std::abs(oa.qacc[d] - ob.qacc[d]));
    }
    for (std::size_t q = 0; q < static_cast<std::size_t>(m.nq); ++q) {
      qpos_diff = std::max(qpos_diff, std::abs(oa.qpos[q] - ob.qpos[q]));
    }
    const Quat root = quat_of(ob.qpos, 3), hip = quat_of(ob.qpos, motion.hip->qpos_adr);
    if (k > 0)
      min_dot = std::min({min_dot, root.coeffs().dot(prev_root.coeffs()), hip.coeffs().dot(prev_hip.coeffs())});
    prev_root = root;
    prev_hip = hip;
  }
  MESSAGE("sign flips: qvel diff " << vel_diff << ", qacc diff " << acc_diff << ", qpos diff " << qpos_diff
                                   << ", smallest dot of consecutive output quaternions " << min_dot);
  CHECK(vel_diff == 0.0);  // the increments take the short way: bit for bit
  CHECK(acc_diff == 0.0);
  CHECK(qpos_diff == 0.0);  // the output in the previous frame's hemisphere
  CHECK(min_dot > 0.99);
}

TEST_CASE("reference velocity: missing and broken frames are bridged, never NaN") {
  const sim::Model& m = humanoid();
  const Motion motion(m);
  const Setting s = kSettings[0];
  ReferenceVelocity::Created made = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
  REQUIRE(made);
  ReferenceVelocity& rv = *made.velocity;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  ReferenceVelocity::Output out;
  // Which frames are broken, and how: every 7th frame one joint or the root;
  // frames 300..304 all of them (a 5-frame dropout); frame 400 a short span.
  auto broken = [](int k) { return (k % 7 == 3) || (k >= 300 && k < 305); };
  double vel_err = 0.0, vel_peak = 0.0, fill_err = 0.0;
  int filled = 0, short_frames = 0;
  bool all_finite = true;
  for (int k = 0; k < 720; ++k) {
    const double t = k * s.dt_s;
    Truth in = motion.at(m, t);
    std::span<const double> span(in.qpos.data(), static_cast<std::size_t>(m.nq));
    if (broken(k)) {
      const auto e = static_cast<std::size_t>(motion.elbow->qpos_adr);
      const auto h = static_cast<std::size_t>(motion.hip->qpos_adr);
      switch ((k / 7) % 4) {
        case 0: in.qpos[e] = nan; break;
        case 1:
          for (std::size_t c = 0; c < 4; ++c) in.qpos[h + c] = 0.0;  // zero norm
          break;
        case 2: in.qpos[0] = inf; break;
        case 3: in.qpos[5] = 1e300; break;  // the root's quaternion
      }
      if (k >= 300) {
        in.qpos[e] = nan;
        in.qpos[h] = nan;
        in.qpos[1] = 1e300;
        in.qpos[3] = nan;
      }
    }
    if (k == 400) {
      span = span.first(5);
      ++short_frames;
    }
    rv.push(span, out);
    for (std::size_t q = 0; q < sim::kMaxQpos; ++q) all_finite = all_finite && std::isfinite(out.qpos[q]);
    for (std::size_t d = 0; d < sim::kMaxDofs; ++d) {
      all_finite = all_finite && std::isfinite(out.qvel[d]) && std::isfinite(out.qacc[d]);
    }
    if (!out.warm) continue;
    const int idx = static_cast<int>(out.index);
    const Truth tr = motion.at(m, idx * s.dt_s);
    const bool expect_missing = broken(idx) || idx == 400;
    CHECK((out.missing_joints > 0) == expect_missing);
    if (idx * s.dt_s < 1.0) continue;
    for (std::size_t d = 0; d < static_cast<std::size_t>(m.nv); ++d) {
      vel_err = std::max(vel_err, std::abs(out.qvel[d] - tr.qvel[d]));
      vel_peak = std::max(vel_peak, std::abs(tr.qvel[d]));
    }
    if (out.missing_joints > 0) {
      ++filled;
      double e = 0.0;
      for (const sim::Body* bb : {motion.elbow, motion.hip, motion.root}) {
        if (bb->joint == sim::JointType::hinge) {
          e = std::max(e, std::abs(out.qpos[static_cast<std::size_t>(bb->qpos_adr)] -
                                   tr.qpos[static_cast<std::size_t>(bb->qpos_adr)]));
        } else {
          const int qa = bb->qpos_adr + (bb->joint == sim::JointType::free ? 3 : 0);
          e = std::max(e, sim::quat_between(quat_of(out.qpos, qa), quat_of(tr.qpos, qa)).norm());
          if (bb->joint == sim::JointType::free) {
            for (std::size_t c = 0; c < 3; ++c) e = std::max(e, std::abs(out.qpos[c] - tr.qpos[c]));
          }
        }
      }
      fill_err = std::max(fill_err, e);
    }
  }
  MESSAGE("broken frames: velocity max err " << vel_err << " (peak " << vel_peak << "), filled frames " << filled
                                             << ", filled joints max err " << fill_err << " (rad or m)");
  CHECK(all_finite);
  CHECK(short_frames == 1);
  CHECK(filled > 50);
  CHECK(vel_err < 0.01 * vel_peak);  // a gap costs the smoother little at this cutoff
  CHECK(fill_err < 1e-3);
}

TEST_CASE("reference velocity: reset forgets the stream, the next is as a fresh instance's") {
  const sim::Model& m = humanoid();
  const Motion motion(m);
  const Setting s = kSettings[0];
  ReferenceVelocity::Created used = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
  ReferenceVelocity::Created fresh = ReferenceVelocity::create(m, s.dt_s, s.cutoff_hz, s.lag);
  REQUIRE(used);
  REQUIRE(fresh);
  ReferenceVelocity::Output ou, of;
  for (int k = 0; k < 300; ++k) used.velocity->push(motion.at(m, k * s.dt_s).qpos, ou);
  REQUIRE(ou.warm);
  used.velocity->reset();
  CHECK(used.velocity->pushed() == 0);
  // The jump: 10 s further into the motion, the root 12 m away and turned.
  bool same = true;
  for (int k = 0; k < 300; ++k) {
    const Truth in = motion.at(m, 10.0 + k * s.dt_s);
    const bool wu = used.velocity->push(in.qpos, ou);
    const bool wf = fresh.velocity->push(in.qpos, of);
    same = same && wu == wf && ou.qpos == of.qpos && ou.qvel == of.qvel && ou.qacc == of.qacc && ou.index == of.index;
    if (k < s.lag) {
      // Warming up: the first sample after the jump, at rest.
      CHECK_FALSE(wu);
      CHECK(ou.index == 0);
      CHECK(ou.qpos == motion.at(m, 10.0).qpos);
      CHECK(max_abs(ou.qvel) == 0.0);
      CHECK(max_abs(ou.qacc) == 0.0);
    }
  }
  CHECK(same);
}
