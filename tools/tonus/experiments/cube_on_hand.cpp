// The cube experiment.
#include "cube_on_hand.hpp"

#include <algorithm>
#include <cmath>

#include "scene.hpp"

namespace tonus::experiments {

using sim::Bone;
using sim::Vec3;

namespace {

struct Run {
  CubeMode mode;
  std::string error;
};

// One mode at one arm curve (min_hz = max_hz = freq when freq > 0).
Run run_mode(const sim::Model& m, const CubeOnHandOptions& opt, avatar::Feedforward ff, double freq_hz) {
  Run run;
  CubeMode& r = run.mode;
  r.mode = ff == avatar::Feedforward::none ? "pd_only" : "pd_ff";
  avatar::AvatarConfig cfg;
  cfg.feedforward = ff;
  if (freq_hz > 0.0) {
    auto& arm = cfg.stiffness.curves[static_cast<std::size_t>(avatar::Group::right_arm)];
    arm.min_hz = arm.max_hz = freq_hz;
  }
  auto made = avatar::AvatarController::create(m, cfg);
  if (!made) {
    run.error = made.error;
    return run;
  }
  avatar::AvatarController& c = *made.controller;
  avatar::TickInput in;
  in.reference = forearm_forward_pose(m);
  in.reference.has_velocity = true;
  in.stiffness.fill(opt.stiffness);
  c.set_stiffness_now(in.stiffness);
  Kinematics fk(m);
  const double dt = m.timestep_s;
  const auto ticks = [&](double s) { return static_cast<int>(std::lround(s / dt)); };

  const auto elbow = static_cast<std::size_t>(m.bodies[sim::index(Bone::RightLowerArm)].dof_adr);
  r.stiffness = opt.stiffness;
  r.arm_frequency_hz = c.mapper().frequency_hz(static_cast<std::size_t>(avatar::Group::right_arm), opt.stiffness);
  r.elbow_kp = c.mapper().kp(elbow);
  r.elbow_kd = c.mapper().kd(elbow);

  const Vec3 ref_hand = shape_centre(m, fk.at(in.reference.qpos), Bone::RightHand);
  double err_sum = 0.0;
  int err_n = 0;
  const int settle = ticks(opt.settle_s);
  for (int k = 0; k < settle; ++k) {
    c.tick(in);
    if (k >= settle - ticks(0.1)) {
      err_sum += (shape_centre(m, c.sim_b(), Bone::RightHand) - ref_hand).norm();
      ++err_n;
    }
  }
  r.hand_error_before_drop_m = err_sum / std::max(err_n, 1);
  const Vec3 before = shape_centre(m, c.sim_b(), Bone::RightHand);

  avatar::DropCube cube;
  cube.target = Bone::RightHand;
  cube.mass_kg = opt.cube_mass_kg;
  cube.edge_m = opt.cube_edge_m;
  cube.height_m = opt.drop_height_m;
  const avatar::SpawnResult sp = c.drop_cube(cube);
  if (!sp.ok()) {
    run.error = "the cube was refused: " + std::string(avatar::to_string(sp.error));
    return run;
  }
  const int after = ticks(opt.after_s);
  std::vector<Vec3> path;
  path.reserve(static_cast<std::size_t>(after));
  int impact = -1;
  bool touching = false;
  for (int k = 0; k < after; ++k) {
    const avatar::TickOutput& o = c.tick(in);
    touching = false;
    for (int e = 0; e < o.nevents; ++e) {
      const auto& ev = o.events[static_cast<std::size_t>(e)];
      if (ev.gift == sp.id && ev.bone == Bone::RightHand) touching = true;
    }
    if (touching && impact < 0) impact = k;
    const Vec3 p = shape_centre(m, c.sim_b(), Bone::RightHand);
    path.push_back(p);
    r.peak_deflection_m = std::max(r.peak_deflection_m, (p - before).norm());
    if (k % 10 == 0) {
      r.t_s.push_back((k + 1) * dt);
      r.hand_dz_m.push_back(p.z() - before.z());
    }
  }
  r.impact_time_s = impact >= 0 ? (impact + 1) * dt : 0.0;
  r.final_deflection_m = (path.back() - before).norm();
  const double band = std::max(0.002, 0.05 * r.peak_deflection_m);
  int last_out = impact;
  for (int k = std::max(impact, 0); k < after; ++k) {
    if ((path[static_cast<std::size_t>(k)] - path.back()).norm() > band) last_out = k;
  }
  r.settling_time_s = impact >= 0 ? (last_out - impact + 1) * dt : opt.after_s;
  const sim::Object* o = nullptr;
  for (const sim::Object& x : c.sim_b().objects) {
    if (x.active) o = &x;
  }
  r.cube_stayed = touching && o != nullptr && o->pos.z() > path.back().z();
  return run;
}

}  // namespace

CubeOnHandResult run_cube_on_hand(const sim::Model& m, const CubeOnHandOptions& opt) {
  CubeOnHandResult res;
  Run a = run_mode(m, opt, avatar::Feedforward::none, 0.0);
  Run b = run_mode(m, opt, avatar::Feedforward::simulation, 0.0);
  if (!a.error.empty() || !b.error.empty()) {
    res.error = a.error.empty() ? b.error : a.error;
    return res;
  }
  res.pd_only = std::move(a.mode);
  res.pd_ff = std::move(b.mode);
  for (const double f : opt.sweep_hz) {
    Run p = run_mode(m, opt, avatar::Feedforward::none, f);
    Run q = run_mode(m, opt, avatar::Feedforward::simulation, f);
    if (!p.error.empty() || !q.error.empty()) {
      res.error = p.error.empty() ? q.error : p.error;
      return res;
    }
    res.sweep.push_back({f, p.mode.cube_stayed, q.mode.cube_stayed, p.mode.peak_deflection_m, q.mode.peak_deflection_m,
                         p.mode.hand_error_before_drop_m, q.mode.hand_error_before_drop_m});
  }
  return res;
}

}  // namespace tonus::experiments
