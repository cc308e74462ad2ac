// The bracing experiment.
#include "brace.hpp"

#include <algorithm>
#include <cmath>

#include "scene.hpp"

namespace tonus::experiments {

using sim::Bone;
using sim::Vec3;

namespace {

std::string run_one(const sim::Model& m, const BraceOptions& opt, Bone bone, double s, BracePoint& p) {
  auto made = avatar::AvatarController::create(m, avatar::AvatarConfig{});
  if (!made) return made.error;
  avatar::AvatarController& c = *made.controller;
  avatar::TickInput in;
  in.reference = arms_down_pose(m);
  in.reference.has_velocity = true;
  in.stiffness.fill(s);
  c.set_stiffness_now(in.stiffness);
  p.stiffness = s;
  p.trunk_frequency_hz = c.mapper().frequency_hz(static_cast<std::size_t>(avatar::Group::trunk), s);
  const double dt = m.timestep_s;
  for (int k = 0; k < static_cast<int>(std::lround(opt.settle_s / dt)); ++k) c.tick(in);
  const Vec3 before = shape_centre(m, c.sim_b(), bone);
  avatar::ThrowBall ball;
  ball.target = bone;
  ball.mass_kg = opt.ball_mass_kg;
  ball.radius_m = opt.ball_radius_m;
  ball.speed_mps = opt.ball_speed_mps;
  ball.lifetime_s = 0.0;
  const avatar::SpawnResult sp = c.throw_ball(ball);
  if (!sp.ok()) return "the ball was refused: " + std::string(avatar::to_string(sp.error));
  int first = -1;
  int peak_at = 0;
  const int n = static_cast<int>(std::lround(opt.after_s / dt));
  for (int k = 0; k < n; ++k) {
    const avatar::TickOutput& o = c.tick(in);
    for (int e = 0; e < o.nevents; ++e) {
      const avatar::ContactEvent& ev = o.events[static_cast<std::size_t>(e)];
      if (!(ev.gift == sp.id)) continue;
      p.impulse_ns += ev.impulse_ns;
      if (first < 0) first = k;
    }
    const double d = (shape_centre(m, c.sim_b(), bone) - before).norm();
    if (d > p.peak_deflection_m) {
      p.peak_deflection_m = d;
      peak_at = k;
    }
    p.final_deflection_m = d;
    if (k % 5 == 0) {
      p.t_s.push_back((k + 1) * dt);
      p.deflection_m.push_back(d);
    }
  }
  p.hit = first >= 0;
  p.time_to_peak_s = p.hit ? (peak_at - first) * dt : 0.0;
  return {};
}

}  // namespace

BraceResult run_brace(const sim::Model& m, const BraceOptions& opt) {
  BraceResult r;
  for (const auto& [name, bone] : {std::pair{"chest", Bone::Chest}, std::pair{"head", Bone::Head}}) {
    BraceTarget t;
    t.name = name;
    t.bone = bone;
    for (const double s : opt.stiffness) {
      BracePoint p;
      if (std::string e = run_one(m, opt, bone, s, p); !e.empty()) {
        r.error = e;
        return r;
      }
      t.points.push_back(std::move(p));
    }
    t.strictly_decreasing = !t.points.empty();
    for (std::size_t i = 0; i < t.points.size(); ++i) {
      t.strictly_decreasing = t.strictly_decreasing && t.points[i].hit;
      if (i > 0)
        t.strictly_decreasing =
            t.strictly_decreasing && t.points[i].peak_deflection_m < t.points[i - 1].peak_deflection_m;
    }
    r.targets.push_back(std::move(t));
  }
  return r;
}

}  // namespace tonus::experiments
