// The tracking experiment.
#include "track.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "scene.hpp"
#include "stats.hpp"
#include "tonus/host/reference/clip_reference.hpp"

namespace tonus::experiments {

using sim::Bone;
using sim::Vec3;

namespace {

constexpr std::array<avatar::Feedforward, 3> kVariants{
    avatar::Feedforward::simulation, avatar::Feedforward::inverse_dynamics, avatar::Feedforward::none};

sim::Quat quat_at(const std::array<double, sim::kMaxQpos>& q, std::size_t a) {
  return {q[a], q[a + 1], q[a + 2], q[a + 3]};
}

void put_quat(std::array<double, sim::kMaxQpos>& q, std::size_t a, const sim::Quat& r) {
  q[a] = r.w();
  q[a + 1] = r.x();
  q[a + 2] = r.y();
  q[a + 3] = r.z();
}

// Catmull-Rom through the frames, so the reference has continuous velocity
// (linear interpolation of a 30 fps clip would ask for infinite accelerations
// at every frame): cubic Hermite on positions and hinges; on rotations the
// same curve as a Bezier of quaternions (tangents from the neighbours'
// rotation vectors, de Casteljau by slerp), which is C1 too.
double hermite(double p0, double p1, double p2, double p3, double u) {
  const double m1 = 0.5 * (p2 - p0), m2 = 0.5 * (p3 - p1);
  const double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * p1 + (u3 - 2 * u2 + u) * m1 + (-2 * u3 + 3 * u2) * p2 + (u3 - u2) * m2;
}

sim::Quat bezier(const sim::Quat& q0, const sim::Quat& q1, const sim::Quat& q2, const sim::Quat& q3, double u) {
  const Vec3 w1 = 0.5 * (sim::quat_between(q1, q2) - sim::quat_between(q1, q0));  // tangent at q1, per frame
  const Vec3 w2 = 0.5 * (sim::quat_between(q2, q3) - sim::quat_between(q2, q1));
  const sim::Quat b1 = q1 * sim::quat_exp(w1 / 3.0), b2 = q2 * sim::quat_exp(-w2 / 3.0);
  const sim::Quat a = q1.slerp(u, b1), b = b1.slerp(u, b2), c = b2.slerp(u, q2);
  const sim::Quat d = a.slerp(u, b), e = b.slerp(u, c);
  return d.slerp(u, e).normalized();
}

void sample(const sim::Model& m, const reference::ClipReference& clip, double t, avatar::ReferencePose& out) {
  const std::size_t last = clip.qpos.size() - 1;
  const double f = std::clamp(t / clip.dt_s, 0.0, static_cast<double>(last));
  const auto i1 = std::min(static_cast<std::size_t>(std::floor(f)), last);
  const std::size_t i0 = i1 > 0 ? i1 - 1 : 0, i2 = std::min(i1 + 1, last), i3 = std::min(i1 + 2, last);
  const double u = f - static_cast<double>(i1);
  const auto& a = clip.qpos[i0];
  const auto& b = clip.qpos[i1];
  const auto& c = clip.qpos[i2];
  const auto& d = clip.qpos[i3];
  for (int i = 0; i < m.nbody; ++i) {
    const sim::Body& body = m.bodies[static_cast<std::size_t>(i)];
    const auto q = static_cast<std::size_t>(body.qpos_adr);
    std::size_t rot = q;
    switch (body.joint) {
      case sim::JointType::free:
        for (std::size_t k = 0; k < 3; ++k) out.qpos[q + k] = hermite(a[q + k], b[q + k], c[q + k], d[q + k], u);
        rot = q + 3;
        [[fallthrough]];
      case sim::JointType::ball:
        put_quat(out.qpos, rot, bezier(quat_at(a, rot), quat_at(b, rot), quat_at(c, rot), quat_at(d, rot), u));
        break;
      case sim::JointType::hinge: out.qpos[q] = hermite(a[q], b[q], c[q], d[q], u); break;
      case sim::JointType::fixed: break;
    }
  }
  out.has_velocity = false;
}

std::string track_variant(const sim::Model& m, const TrackOptions& opt, const reference::ClipReference& clip,
                          double duration, VariantTrack& r) {
  avatar::AvatarConfig cfg;
  cfg.feedforward = r.variant;
  auto made = avatar::AvatarController::create(m, cfg);
  if (!made) return made.error;
  avatar::AvatarController& c = *made.controller;
  avatar::TickInput in;
  in.stiffness.fill(opt.stiffness);
  c.set_stiffness_now(in.stiffness);
  Kinematics fk(m);
  const double dt = m.timestep_s;
  const auto n = static_cast<std::size_t>(std::floor(duration / dt));
  const double t0_s = clip.dt_s * static_cast<double>(clip.first_frame);  // after a leading T-pose
  std::vector<double> us;
  us.reserve(n);
  std::array<double, sim::kBoneCount> sum2{};
  double all2 = 0.0, hand2 = 0.0;
  std::size_t counted = 0;
  const std::size_t skip = static_cast<std::size_t>(std::lround(0.5 / dt));  // the first 0.5 s: the start from rest
  for (std::size_t k = 0; k < n; ++k) {
    sample(m, clip, t0_s + static_cast<double>(k) * dt, in.reference);
    const auto t0 = std::chrono::steady_clock::now();
    const avatar::TickOutput& o = c.tick(in);
    const auto t1 = std::chrono::steady_clock::now();
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    if (k < skip || (o.flags & avatar::kWarmingUp) != 0) continue;
    ++counted;
    for (std::size_t b = 1; b < sim::kBoneCount; ++b) {
      const double e = o.deviation_rad[b];
      sum2[b] += e * e;
      all2 += e * e;
      r.max_rad = std::max(r.max_rad, e);
    }
    const sim::Data& ref = fk.at(o.reference_qpos);
    for (const Bone h : {Bone::LeftHand, Bone::RightHand}) {
      const double e = (shape_centre(m, c.sim_b(), h) - shape_centre(m, ref, h)).norm();
      hand2 += e * e;
    }
  }
  const double nc = static_cast<double>(std::max<std::size_t>(counted, 1));
  for (std::size_t b = 1; b < sim::kBoneCount; ++b) r.rms_rad[b] = std::sqrt(sum2[b] / nc);
  r.rms_all_rad = std::sqrt(all2 / (nc * static_cast<double>(sim::kBoneCount - 1)));
  r.hand_rms_m = std::sqrt(hand2 / (2.0 * nc));
  r.lag_s = r.variant == avatar::Feedforward::inverse_dynamics ? cfg.id_lag_ticks * dt : 0.0;
  double total = 0.0;
  for (const double x : us) total += x;
  r.tick_mean_us = total / static_cast<double>(std::max<std::size_t>(us.size(), 1));
  r.tick_p50_us = percentile(us, 0.5);
  r.tick_p99_us = percentile(us, 0.99);
  r.tick_max_us = us.empty() ? 0.0 : *std::max_element(us.begin(), us.end());
  r.jumps = c.stats().reference_jumps;
  r.clamped = c.stats().reference_clamped;
  r.resets = c.stats().resets_a + c.stats().resets_b;
  return {};
}

std::string impact(const sim::Model& m, const TrackOptions& opt, ImpactReaction& r) {
  avatar::AvatarConfig cfg;
  cfg.feedforward = r.variant;
  auto made = avatar::AvatarController::create(m, cfg);
  if (!made) return made.error;
  avatar::AvatarController& c = *made.controller;
  avatar::TickInput in;
  in.reference = arms_down_pose(m);
  in.reference.has_velocity = true;
  in.stiffness.fill(opt.stiffness);
  c.set_stiffness_now(in.stiffness);
  for (int k = 0; k < 500; ++k) c.tick(in);  // also fills (b)'s lag
  const Vec3 before = shape_centre(m, c.sim_b(), Bone::Chest);
  avatar::ThrowBall ball;
  ball.target = Bone::Chest;
  const avatar::SpawnResult sp = c.throw_ball(ball);
  if (!sp.ok()) return "the ball was refused";
  for (int k = 0; k < 1000; ++k) {
    const avatar::TickOutput& o = c.tick(in);
    for (int e = 0; e < o.nevents; ++e) {
      if (o.events[static_cast<std::size_t>(e)].gift == sp.id)
        r.impulse_ns += o.events[static_cast<std::size_t>(e)].impulse_ns;
    }
    r.peak_deflection_m = std::max(r.peak_deflection_m, (shape_centre(m, c.sim_b(), Bone::Chest) - before).norm());
  }
  return {};
}

}  // namespace

TrackResult run_track(const sim::Model& m, const TrackOptions& opt) {
  TrackResult res;
  for (const std::string& path : opt.clips) {
    const reference::ClipReference clip = reference::clip_to_reference(m, path);
    if (!clip.ok()) {
      res.error = path + ": " + clip.error;
      return res;
    }
    if (clip.qpos.size() < 2 || !(clip.dt_s > 0.0)) {
      res.error = path + ": too short to follow";
      return res;
    }
    ClipTrack ct;
    ct.clip = std::filesystem::path(path).filename().string();
    ct.frames = clip.qpos.size();
    ct.frames_clamped = clip.frames_clamped;
    ct.messages = clip.messages;
    ct.duration_s = std::min(opt.max_seconds, clip.dt_s * static_cast<double>(clip.qpos.size() - 1 - clip.first_frame));
    for (const avatar::Feedforward v : kVariants) {
      VariantTrack vt;
      vt.variant = v;
      if (std::string e = track_variant(m, opt, clip, ct.duration_s, vt); !e.empty()) {
        res.error = e;
        return res;
      }
      ct.variants.push_back(vt);
    }
    res.clips.push_back(std::move(ct));
  }
  for (const avatar::Feedforward v : kVariants) {
    ImpactReaction r;
    r.variant = v;
    if (std::string e = impact(m, opt, r); !e.empty()) {
      res.error = e;
      return res;
    }
    res.impact.push_back(r);
  }
  return res;
}

}  // namespace tonus::experiments
