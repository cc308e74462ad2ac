// BodyRetarget::solve allocates nothing: every malloc family call and every
// operator new is counted (tests/support/allocation_counter) over 10,000
// frames, good, missing and broken input mixed.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "support/allocation_counter.hpp"
#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;
using sim::Quat;
using sim::Vec3;

TEST_CASE("body retarget: 10,000 solves allocate nothing") {
  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  REQUIRE(built);
  const sim::Model& m = *built.model;
  const reference::SourceSkeleton src = reference::a_pose_variant(reference::skeleton_of(m), 0.7, 0.95, 1.05);
  const reference::BodyRetargetBuild b = reference::BodyRetarget::create(m, src);
  REQUIRE_MESSAGE(b.ok(), b.error);
  const reference::BodyRetarget& rt = *b.retarget;

  // The frames, made before counting: waving arms, bending knees, a turning body, and every 7th broken.
  std::vector<reference::BodySample> frames(500);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const double t = static_cast<double>(f) / 100.0;
    reference::BodySample& s = frames[f];
    s.present = src.present;
    s.local = src.rest_rotation;
    s.root_present = true;
    s.root_position = Vec3(0.3 * t, 0.0, src.offset[0].z() - 0.1 * std::sin(t));
    s.root_rotation = Quat(Eigen::AngleAxisd(t, Vec3::UnitZ()));
    s.local[sim::index(sim::Bone::LeftUpperArm)] = src.rest_rotation[sim::index(sim::Bone::LeftUpperArm)] *
                                                   Quat(Eigen::AngleAxisd(std::sin(3 * t), Vec3::UnitX()));
    s.local[sim::index(sim::Bone::LeftLowerLeg)] = Quat(Eigen::AngleAxisd(1.0 + std::sin(2 * t), Vec3::UnitY()));
    if (f % 7 == 3) s.local[sim::index(sim::Bone::Chest)] = Quat(std::numeric_limits<double>::quiet_NaN(), 0, 0, 0);
    if (f % 11 == 5) s.present[sim::index(sim::Bone::Head)] = false;
    if (f % 13 == 2) s.root_position.x() = 1e300;
  }
  reference::BodyRetargetState state;
  std::array<double, sim::kMaxQpos> qpos{};
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  tonus::test::start_counting_allocations();
  int written = 0, flagged = 0;
  for (int k = 0; k < 10000; ++k) {
    const reference::BodyStatus st = rt.solve(frames[static_cast<std::size_t>(k) % frames.size()], state, qpos);
    written += st.written ? 1 : 0;
    flagged += st.input_valid() ? 0 : 1;
  }
  const long allocations = tonus::test::stop_counting_allocations();
  MESSAGE("allocations during 10,000 solves: " << allocations << " (" << flagged << " frames flagged)");
  CHECK(allocations == 0);
  CHECK(written == 10000);
  CHECK(flagged > 0);
  for (int k = 0; k < m.nq; ++k) CHECK(std::isfinite(qpos[static_cast<std::size_t>(k)]));
}
