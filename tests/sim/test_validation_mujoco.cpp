// Validation against an independent reference: MuJoCo 2.2.2 running our
// humanoid exported as MJCF, same integrator, same state; and conservation
// of energy and momentum over 10 s.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "sim_fixtures.hpp"
#include "support/sanitized.hpp"
#include "tonus/sim/mjcf.hpp"

using namespace tonus::sim;
using test::humanoid;
using test::Mujoco;

namespace {

Features contact_free(bool gravity) {
  Features f;
  f.contacts = false;
  f.limits = false;
  f.gravity = gravity;
  return f;
}

void random_velocities(const Model& m, Data& d, unsigned seed, double scale = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, scale);  // rad/s and m/s
  for (int k = 0; k < m.nv; ++k) d.qvel[static_cast<std::size_t>(k)] = n(rng);
}

void random_pose(const Model& m, Data& d, unsigned seed) { test::random_joint_pose(m, d.qpos, seed, 0.3); }

struct Comparison {
  double at_100ms = 0.0;
  double over_500ms = 0.0;
};

Comparison compare_with_mujoco(Integrator integrator, bool gravity, unsigned seed) {
  const auto model = humanoid(contact_free(gravity), integrator);
  auto data = make_data(*model);
  random_pose(*model, *data, seed);
  random_velocities(*model, *data, seed + 1);
  MjcfOptions opt;
  opt.integrator_euler = integrator == Integrator::euler;
  Mujoco mj(to_mjcf(*model, opt));
  REQUIRE_MESSAGE(mj.ok(), mj.error());
  REQUIRE(mj.m()->nq == model->nq);
  REQUIRE(mj.m()->nv == model->nv);
  for (int k = 0; k < model->nq; ++k) mj.d()->qpos[k] = data->qpos[static_cast<std::size_t>(k)];
  for (int k = 0; k < model->nv; ++k) mj.d()->qvel[k] = data->qvel[static_cast<std::size_t>(k)];
  const StepInputs in = test::passive_inputs(*model);
  Comparison c;
  for (int s = 1; s <= 500; ++s) {
    REQUIRE(step(*model, *data, in) == StepStatus::ok);
    mj_step(mj.m(), mj.d());
    const double diff = test::max_joint_difference(*model, data->qpos.data(), mj.d()->qpos);
    c.over_500ms = std::max(c.over_500ms, diff);
    if (s == 100) c.at_100ms = diff;
  }
  return c;
}

}  // namespace

TEST_CASE("the exported humanoid loads in MuJoCo with the same masses, inertias and dofs") {
  const auto model = humanoid(Features{});
  Mujoco mj(to_mjcf(*model));
  REQUIRE_MESSAGE(mj.ok(), mj.error());
  CHECK(mj.m()->nv == model->nv);
  CHECK(mj.m()->nq == model->nq);
  CHECK(mj.m()->nbody == model->nbody + 1);  // MuJoCo counts the world
  for (int i = 0; i < model->nbody; ++i) {
    const Body& b = model->bodies[static_cast<std::size_t>(i)];
    CHECK(mj.m()->body_mass[i + 1] == doctest::Approx(b.mass_kg).epsilon(1e-12));
    // MuJoCo stores principal moments; their sum is the trace, frame-free.
    const double* pi = mj.m()->body_inertia + 3 * static_cast<std::ptrdiff_t>(i + 1);
    CHECK(pi[0] + pi[1] + pi[2] == doctest::Approx(b.inertia.trace()).epsilon(1e-9));
  }
}

TEST_CASE("contact-free humanoid, zero gravity, random velocities: Euler trajectories match MuJoCo's") {
  const Comparison c = compare_with_mujoco(Integrator::euler, false, 1);
  MESSAGE("Euler vs MuJoCo: max joint difference " << c.at_100ms << " rad at 0.1 s, " << c.over_500ms
                                                   << " rad over 0.5 s");
  CHECK(c.at_100ms < 1e-3);    // the goal
  CHECK(c.over_500ms < 1e-6);  // what the identical algorithm reaches, with margin for rounding
}

TEST_CASE("contact-free humanoid, zero gravity, random velocities: RK4 trajectories match MuJoCo's") {
  const Comparison c = compare_with_mujoco(Integrator::rk4, false, 2);
  MESSAGE("RK4 vs MuJoCo: max joint difference " << c.at_100ms << " rad at 0.1 s, " << c.over_500ms
                                                 << " rad over 0.5 s");
  CHECK(c.at_100ms < 1e-3);
  CHECK(c.over_500ms < 1e-6);
}

TEST_CASE("with gravity, from a random pose, Euler trajectories match MuJoCo's") {
  const Comparison c = compare_with_mujoco(Integrator::euler, true, 3);
  MESSAGE("Euler with gravity vs MuJoCo: max joint difference " << c.over_500ms << " rad over 0.5 s");
  CHECK(c.over_500ms < 1e-6);
}

TEST_CASE("energy and momentum over 10 s at dt = 1 ms, zero gravity, random velocities" *
          tonus::test::heavy_under_sanitizers()) {
  // RK4 (the validation integrator) under violent motion: N(0, 1) rad/s on every dof.
  // Euler (the real-time one) is first order: its drift is reported at N(0, 0.3);
  // without any damping its velocity-product terms pump energy into light links.
  for (const Integrator integrator : {Integrator::rk4, Integrator::euler}) {
    const bool rk4 = integrator == Integrator::rk4;
    const auto model = humanoid(contact_free(false), integrator);
    auto data = make_data(*model);
    random_velocities(*model, *data, 7, rk4 ? 1.0 : 0.3);
    forward_kinematics(*model, *data);
    const double e0 = energy(*model, *data).total_j();
    const Momentum p0 = momentum(*model, *data);
    const StepInputs in = test::passive_inputs(*model);
    double worst = 0.0;
    for (int s = 0; s < 10000; ++s) {
      REQUIRE(step(*model, *data, in) == StepStatus::ok);
      worst = std::max(worst, std::abs(energy(*model, *data).total_j() - e0) / e0);
    }
    const Momentum p = momentum(*model, *data);
    const double dp = (p.linear - p0.linear).norm() / p0.linear.norm();
    const double dl = (p.angular - p0.angular).norm() / p0.angular.norm();
    MESSAGE(std::string(rk4 ? "RK4, N(0,1)" : "Euler, N(0,0.3)")
            << ": max relative energy drift " << worst << ", relative change of linear momentum " << dp
            << ", of angular momentum " << dl << " after 10 s");
    if (rk4) {
      CHECK(worst < 1e-3);  // the goal
      CHECK(dp < 1e-3);
      CHECK(dl < 1e-3);
    } else {
      CHECK(worst < 0.05);
    }
  }
}

TEST_CASE("gravity-compensated hold: feedforward = inverse dynamics of the pose, Kp = 0, the avatar stays still") {
  const auto model = humanoid(Features{.gravity = true, .contacts = false, .limits = false, .self_collision = false});
  for (const bool rest : {true, false}) {
    auto data = make_data(*model);
    set_root_mode(*data, RootMode::fixed);
    if (!rest) random_pose(*model, *data, 9);
    forward_kinematics(*model, *data);
    const auto q0 = data->qpos;
    StepInputs in = test::passive_inputs(*model);
    std::array<double, kMaxDofs> zero{};
    inverse_dynamics(*model, *data, zero, in.tau_ff);
    for (int s = 0; s < 1000; ++s) REQUIRE(step(*model, *data, in) == StepStatus::ok);
    const double drift = test::max_joint_difference(*model, q0.data(), data->qpos.data());
    MESSAGE(std::string(rest ? "rest pose" : "random pose") << ": drift after 1 s " << drift << " rad");
    CHECK(drift < 1e-4);
    // Without the feedforward the same pose falls: the check above can fail.
    if (rest) {
      auto fall = make_data(*model);
      set_root_mode(*fall, RootMode::fixed);
      const StepInputs none = test::passive_inputs(*model);
      for (int s = 0; s < 1000; ++s) step(*model, *fall, none);
      CHECK(test::max_joint_difference(*model, q0.data(), fall->qpos.data()) > 0.1);
    }
  }
}
