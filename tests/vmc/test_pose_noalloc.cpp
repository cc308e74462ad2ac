// pose_from_qpos allocates nothing: every malloc family call and every
// operator new is counted (tests/support/allocation_counter) over 10,000
// poses, bad ones mixed in. Only the pose building: liblo allocates when it
// builds and sends the messages.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "support/allocation_counter.hpp"
#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;

TEST_CASE("vmc pose out: 10,000 poses from qpos allocate nothing") {
  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  REQUIRE(built);
  const sim::Model& m = *built.model;
  // The configurations, made before counting: the head and an elbow turning, every 9th broken.
  std::vector<std::vector<double>> qs(100, std::vector<double>(m.qpos0.begin(), m.qpos0.begin() + m.nq));
  const sim::Body& head = m.bodies[sim::index(sim::Bone::Head)];
  const sim::Body& elbow = m.bodies[sim::index(sim::Bone::LeftLowerArm)];
  for (std::size_t f = 0; f < qs.size(); ++f) {
    const double t = static_cast<double>(f) / 10.0;
    const sim::Quat q(Eigen::AngleAxisd(0.5 * std::sin(t), sim::Vec3::UnitZ()));
    const auto a = static_cast<std::size_t>(head.qpos_adr);
    qs[f][a] = q.w();
    qs[f][a + 1] = q.x();
    qs[f][a + 2] = q.y();
    qs[f][a + 3] = q.z();
    qs[f][static_cast<std::size_t>(elbow.qpos_adr)] = 0.5 + 0.4 * std::sin(t);
    if (f % 9 == 4) qs[f][2] = std::numeric_limits<double>::quiet_NaN();
  }
  vmc::VmcPose pose;
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  tonus::test::start_counting_allocations();
  int written = 0;
  for (int k = 0; k < 10000; ++k) {
    written += vmc::pose_from_qpos(m, qs[static_cast<std::size_t>(k) % qs.size()], pose) ? 1 : 0;
  }
  const long allocations = tonus::test::stop_counting_allocations();
  MESSAGE("allocations during 10,000 poses: " << allocations << " (" << 10000 - written << " refused)");
  CHECK(allocations == 0);
  CHECK(written > 8000);
  CHECK(written < 10000);
}
