// Rigid-body algorithms checked against each other (Pinocchio's practice) and
// against closed forms: CRBA vs RNEA, the sparse LTDL solve vs a dense
// Cholesky, forward vs inverse dynamics, a pendulum.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

#include "sim_fixtures.hpp"

using namespace tonus::sim;
using test::humanoid;

namespace {

// A humanoid in a random configuration with random velocities.
void randomize(const Model& m, Data& d, std::mt19937& rng, double vel_scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < m.nbody; ++i) {
    const Body& b = m.bodies[static_cast<std::size_t>(i)];
    auto q = d.qpos.begin() + b.qpos_adr;
    if (b.joint == JointType::ball || b.joint == JointType::free) {
      const int off = b.joint == JointType::free ? 3 : 0;
      const Quat r = quat_exp(Vec3(n(rng), n(rng), n(rng)) * 0.5);
      q[off] = r.w();
      q[off + 1] = r.x();
      q[off + 2] = r.y();
      q[off + 3] = r.z();
    } else if (b.joint == JointType::hinge) {
      q[0] = 0.5 * n(rng);
    }
  }
  for (int k = 0; k < m.nv; ++k) d.qvel[static_cast<std::size_t>(k)] = vel_scale * n(rng);
  forward_kinematics(m, d);
}

Eigen::MatrixXd dense_mass(const Model& m, const Data& d) {
  Eigen::MatrixXd M(m.nv, m.nv);
  M.setZero();
  for (int k = 0; k < m.nv; ++k) {
    for (int j = k; j >= 0; j = m.dof_parent[static_cast<std::size_t>(j)]) {
      M(k, j) = M(j, k) =
          d.mass[static_cast<std::size_t>(k) * static_cast<std::size_t>(m.nv) + static_cast<std::size_t>(j)];
    }
  }
  return M;
}

}  // namespace

TEST_CASE("CRBA: each column of M is the inverse dynamics of a unit acceleration minus the bias") {
  Features f;
  const auto model = humanoid(f);
  auto data = make_data(*model);
  std::mt19937 rng(11);
  randomize(*model, *data, rng, 1.0);
  mass_matrix(*model, *data);
  const Eigen::MatrixXd M = dense_mass(*model, *data);
  std::array<double, kMaxDofs> zero{}, bias{}, tau{}, unit{};
  inverse_dynamics(*model, *data, zero, bias);
  double worst = 0.0;
  for (int k = 0; k < model->nv; ++k) {
    unit.fill(0.0);
    unit[static_cast<std::size_t>(k)] = 1.0;
    inverse_dynamics(*model, *data, unit, tau);
    for (int j = 0; j < model->nv; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      worst = std::max(worst, std::abs(tau[ju] - bias[ju] - M(j, k)));
    }
  }
  CHECK(worst < 1e-10);
  // Symmetric positive definite, and zero off the tree's paths (CRBA never writes there).
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  CHECK(llt.info() == Eigen::Success);
}

TEST_CASE("forward dynamics (sparse LTDL) inverts inverse dynamics, and agrees with a dense Cholesky") {
  Features f;
  const auto model = humanoid(f);
  auto data = make_data(*model);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 10.0);
  for (int trial = 0; trial < 5; ++trial) {
    randomize(*model, *data, rng, 2.0);
    std::array<double, kMaxDofs> tau{}, qacc{}, back{};
    for (int k = 0; k < model->nv; ++k) tau[static_cast<std::size_t>(k)] = n(rng);
    forward_dynamics(*model, *data, tau, qacc);
    inverse_dynamics(*model, *data, qacc, back);
    const Eigen::MatrixXd M = dense_mass(*model, *data);
    Eigen::VectorXd rhs(model->nv);
    for (int k = 0; k < model->nv; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      rhs(k) = tau[ku] - data->bias[ku];
    }
    const Eigen::VectorXd dense = M.llt().solve(rhs);
    for (int k = 0; k < model->nv; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      CHECK(back[ku] == doctest::Approx(tau[ku]).epsilon(1e-9).scale(1.0));
      CHECK(qacc[ku] == doctest::Approx(dense(k)).epsilon(1e-9).scale(1.0));
    }
  }
}

TEST_CASE("a compound pendulum accelerates as -m g l sin(theta) / I_pivot") {
  const double mass = 2.0, len = 0.7, theta = 0.9;
  ModelBuilder mb;
  BodySpec rod;
  rod.name = "rod";
  rod.joint = JointType::hinge;
  rod.hinge_axis = Vec3::UnitY();
  rod.mass_kg = mass;
  rod.com = Vec3(0, 0, -len);
  rod.inertia = cylinder_inertia(mass, 0.02, 0.1);
  mb.add_body(rod);
  Features f;
  f.contacts = false;
  mb.features(f);
  const BuildResult r = mb.build();
  REQUIRE(r);
  auto d = make_data(*r.model);
  d->qpos[0] = theta;
  forward_kinematics(*r.model, *d);
  std::array<double, kMaxDofs> tau{}, qacc{};
  forward_dynamics(*r.model, *d, tau, qacc);
  const double i_pivot = rod.inertia(1, 1) + mass * len * len;
  CHECK(qacc[0] == doctest::Approx(-mass * 9.81 * len * std::sin(theta) / i_pivot).epsilon(1e-12));
}

TEST_CASE("a free body in zero gravity keeps its momentum under torque-free tumbling (RK4)") {
  ModelBuilder mb;
  BodySpec box;
  box.name = "box";
  box.joint = JointType::free;
  box.mass_kg = 3.0;
  box.com = Vec3(0.05, -0.02, 0.01);  // off the joint, so the linear and angular parts couple
  box.inertia = box_inertia(3.0, Vec3(0.3, 0.1, 0.05));
  mb.add_body(box);
  Features f;
  f.contacts = f.limits = f.gravity = false;
  mb.features(f).integrator(Integrator::rk4);
  const BuildResult r = mb.build();
  REQUIRE(r);
  auto d = make_data(*r.model);
  const double v0[6] = {0.3, -0.2, 0.1, 2.0, 0.5, -1.0};  // spinning near the unstable middle axis
  for (std::size_t k = 0; k < 6; ++k) d->qvel[k] = v0[k];
  forward_kinematics(*r.model, *d);
  const Momentum p0 = momentum(*r.model, *d);
  const double e0 = energy(*r.model, *d).total_j();
  const StepInputs in = test::passive_inputs(*r.model);
  for (int s = 0; s < 5000; ++s) REQUIRE(step(*r.model, *d, in) == StepStatus::ok);
  const Momentum p = momentum(*r.model, *d);
  // RK4 conserves neither exactly; a wrong bias term would miss by orders of magnitude more.
  CHECK((p.linear - p0.linear).norm() < 1e-6 * p0.linear.norm());
  CHECK((p.angular - p0.angular).norm() < 1e-5 * p0.angular.norm());
  CHECK(std::abs(energy(*r.model, *d).total_j() - e0) < 1e-6 * e0);
}
