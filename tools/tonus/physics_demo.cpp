#include "physics_demo.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <vector>

#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/mjcf.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::tools {
namespace {

using namespace tonus::sim;

double vertical_force_on(const Data& d, int slot) {
  double f = 0.0;
  for (int i = 0; i < d.ncon; ++i) {
    const Contact& c = d.contacts[static_cast<std::size_t>(i)];
    if (c.a.kind == ContactSide::Kind::object && c.a.index == slot) f += c.force_world.z();
    if (c.b.kind == ContactSide::Kind::object && c.b.index == slot) f -= c.force_world.z();
  }
  return f;
}

}  // namespace

int run_physics_demo(const PhysicsDemoOptions& opt) {
  HumanoidSpec spec;
  spec.height_m = opt.height_m;
  spec.mass_kg = opt.mass_kg;
  spec.drive_frequency_hz = opt.hold_hz;
  const BuildResult built = build_humanoid(spec);
  if (!built) {
    fmt::print(stderr, "tonus physics: {}\n", built.error);
    return 1;
  }
  const Model& model = *built.model;
  auto data = make_data(model);
  StepInputs in = make_inputs(model);
  const double dt = model.timestep_s;

  fmt::print("tonus physics: humanoid of {} bodies, {} dofs, {:.1f} kg, {:.2f} m; dt = {:.1f} ms, {:.0f} Hz hold\n",
             model.nbody, model.nv, model.total_mass_kg(), opt.height_m, dt * 1e3, opt.hold_hz);

  const std::size_t hand = index(Bone::LeftHand);
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.04));
  cube.mass_kg = 1.0;
  cube.material.friction = 1.0;
  cube.pos = data->xgeom[hand].pos + Vec3(0, 0, model.geoms[hand].shape.half_extents_m.z() + 0.04 + 0.05);
  const AddObjectResult cube_added = add_object(*data, cube);
  if (cube_added.error != ObjectError::none) {
    fmt::print(stderr, "tonus physics: cube: {}\n", to_string(cube_added.error));
    return 1;
  }
  if (!opt.mjcf_path.empty()) {
    MjcfOptions mo;
    mo.drives_as_springs = true;
    mo.objects_from = data.get();
    std::ofstream out(opt.mjcf_path);
    out << to_mjcf(model, mo);
    if (!out) {
      fmt::print(stderr, "tonus physics: cannot write {}\n", opt.mjcf_path);
      return 1;
    }
    fmt::print("  model written as MJCF to {}\n", opt.mjcf_path);
  }

  ObjectHandle ball{};
  double ball_in = 0.0, ball_out = 0.0;
  std::vector<double> cost_us;
  const auto steps = static_cast<int>(std::lround(opt.seconds / dt));
  cost_us.reserve(static_cast<std::size_t>(steps));
  int diverged = 0;
  double lowest_hips = data->qpos[2];
  double settled_speed = -1.0, settled_support = 0.0;
  const int ball_step = static_cast<int>(1.0 / dt);
  for (int s = 0; s < steps; ++s) {
    if (s == ball_step) {
      // The cube has had 1 s to land and settle: is it at rest, carried by the hand?
      if (const Object* c = find_object(*data, cube_added.handle)) settled_speed = c->lin_vel.norm();
      settled_support = vertical_force_on(*data, cube_added.handle.slot);
    }
    if (s == ball_step && opt.ball_speed_mps > 0.0) {
      ObjectSpec b;
      b.shape = Shape::sphere(0.06);
      b.mass_kg = 0.45;  // a football
      b.material.restitution = 0.6;
      b.pos = data->xgeom[index(Bone::Chest)].pos + Vec3(0.8, 0.05, 0.0);
      b.lin_vel = Vec3(-opt.ball_speed_mps, 0, 0);
      ball = add_object(*data, b).handle;
      ball_in = opt.ball_speed_mps;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const StepStatus st = step(model, *data, in);
    const auto t1 = std::chrono::steady_clock::now();
    cost_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    if (st == StepStatus::diverged) ++diverged;
    lowest_hips = std::min(lowest_hips, data->qpos[2]);
    if (const Object* b = find_object(*data, ball)) ball_out = std::max(ball_out, b->lin_vel.x());
  }

  const Object* c = find_object(*data, cube_added.handle);
  const double weight = 9.81 * cube.mass_kg;
  const bool cube_rests =
      settled_speed >= 0.0 && settled_speed < 0.01 && std::abs(settled_support - weight) < 0.05 * weight;
  const double cube_to_hand = c != nullptr ? (c->pos - data->xgeom[hand].pos).norm() : 1e9;
  const bool cube_kept = cube_to_hand < 0.2;
  std::sort(cost_us.begin(), cost_us.end());
  const auto pct = [&](double p) {
    return cost_us[static_cast<std::size_t>(p * static_cast<double>(cost_us.size() - 1))];
  };
  double mean = 0.0;
  for (double x : cost_us) mean += x;
  mean /= static_cast<double>(cost_us.size());

  fmt::print("  {:.1f} s simulated in {} steps, {} contacts at the end, {} diverged steps\n", opt.seconds, steps,
             data->ncon, diverged);
  if (settled_speed >= 0.0) {
    fmt::print("  cube on the left hand after 1 s: {} ({:.4f} m/s), supported by {:.2f} N for a weight of {:.2f} N\n",
               cube_rests ? "at rest" : "NOT at rest", settled_speed, settled_support, weight);
  }
  fmt::print("  cube at the end: {} the hand ({:.3f} m from its centre)\n", cube_kept ? "still on" : "OFF",
             cube_to_hand);
  if (ball_in > 0.0) {
    fmt::print("  ball thrown at the chest at {:.1f} m/s, bounced back at {:.2f} m/s\n", ball_in, ball_out);
  }
  fmt::print("  hips height {:.3f} m (lowest {:.3f} m, rest {:.3f} m): {}\n", data->qpos[2], lowest_hips,
             model.qpos0[2], data->qpos[2] > 0.9 * model.qpos0[2] ? "upright" : "FELL");
  fmt::print("  step cost: mean {:.1f} us, median {:.1f} us, 99th percentile {:.1f} us, max {:.1f} us\n", mean,
             pct(0.5), pct(0.99), cost_us.back());
  fmt::print("  diagnostics: {} contact overflows, {} unconverged solves, {} torque saturations, {} bad inputs\n",
             data->diag.contact_overflow, data->diag.solver_unconverged, data->diag.torque_saturations,
             data->diag.bad_inputs);
  const bool upright = data->qpos[2] > 0.9 * model.qpos0[2];
  const bool settled_check = opt.seconds <= 1.0 || cube_rests;
  return diverged == 0 && settled_check && cube_kept && upright ? 0 : 1;
}

}  // namespace tonus::tools
