// ReferenceVelocity::push allocates nothing: every malloc family call and
// every operator new is counted (tests/support/allocation_counter) over 10,000
// frames at the avatar's tick, good, missing and broken input mixed, with
// resets.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "support/allocation_counter.hpp"
#include "tonus/host/reference/reference_velocity.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;
using sim::Quat;
using sim::Vec3;

TEST_CASE("reference velocity: 10,000 pushes allocate nothing") {
  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  REQUIRE(built);
  const sim::Model& m = *built.model;
  reference::ReferenceVelocity::Created made = reference::ReferenceVelocity::create(m, 1e-3, 8.0, 60);
  REQUIRE_MESSAGE(made, made.error);
  reference::ReferenceVelocity& rv = *made.velocity;

  // The frames, made before counting: every ball joint and the root turning,
  // hinges waving, the root walking; every 13th frame broken, sign flips.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::array<double, sim::kMaxQpos>> frames(1000, m.qpos0);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const double t = static_cast<double>(f) * 1e-3;
    std::array<double, sim::kMaxQpos>& q = frames[f];
    for (int b = 0; b < m.nbody; ++b) {
      const sim::Body& body = m.bodies[static_cast<std::size_t>(b)];
      auto a = static_cast<std::size_t>(body.qpos_adr);
      const double phase = 0.3 * b;
      if (body.joint == sim::JointType::free) {
        q[a] = 1.2 * t;
        q[a + 1] = 0.05 * std::sin(6 * t);
        q[a + 2] = 0.9;
        a += 3;
      }
      if (body.joint == sim::JointType::free || body.joint == sim::JointType::ball) {
        const Quat r = Quat(Eigen::AngleAxisd(0.5 * std::sin(3 * t + phase), Vec3::UnitZ())) *
                       Quat(Eigen::AngleAxisd(0.4 * std::sin(4 * t + phase), Vec3::UnitX()));
        const double sign = (f % 2 == 1) ? -1.0 : 1.0;
        q[a] = sign * r.w();
        q[a + 1] = sign * r.x();
        q[a + 2] = sign * r.y();
        q[a + 3] = sign * r.z();
      }
      if (body.joint == sim::JointType::hinge) q[a] = 0.7 + 0.5 * std::sin(5 * t + phase);
    }
    if (f % 13 == 5) q[static_cast<std::size_t>(m.bodies[3].qpos_adr)] = nan;
    if (f % 17 == 2) q[0] = 1e300;
  }

  reference::ReferenceVelocity::Output out;
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  tonus::test::start_counting_allocations();
  int warm = 0;
  for (int k = 0; k < 10000; ++k) {
    if (k % 2500 == 2499) rv.reset();
    warm += rv.push(frames[static_cast<std::size_t>(k) % frames.size()], out) ? 1 : 0;
  }
  const long allocations = tonus::test::stop_counting_allocations();
  MESSAGE("allocations during 10,000 pushes: " << allocations << " (" << warm << " warm)");
  CHECK(allocations == 0);
  CHECK(warm > 9000);
  for (std::size_t k = 0; k < sim::kMaxQpos; ++k) CHECK(std::isfinite(out.qpos[k]));
  for (std::size_t k = 0; k < sim::kMaxDofs; ++k) CHECK(std::isfinite(out.qvel[k]));
}
