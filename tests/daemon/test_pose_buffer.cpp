// The tracker jitter buffer on the humanoid: interpolation at the physics
// time against closed forms, then hold, ease to neutral, and recovery.
#include <doctest/doctest.h>

#include <cmath>

#include "tonus/host/daemon/pose_buffer.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;
using namespace tonus::daemon;
using sim::Bone;

namespace {

const sim::Model& humanoid() {
  static const std::unique_ptr<sim::Model> m = [] {
    sim::BuildResult r = sim::build_humanoid(sim::HumanoidSpec{});
    REQUIRE(r);
    return std::move(r.model);
  }();
  return *m;
}

std::size_t adr(Bone b) { return static_cast<std::size_t>(humanoid().bodies[sim::index(b)].qpos_adr); }

sim::Quat quat(const Qpos& q, std::size_t a) { return {q[a], q[a + 1], q[a + 2], q[a + 3]}; }

void set_quat(Qpos& q, std::size_t a, const sim::Quat& r) {
  q[a] = r.w();
  q[a + 1] = r.x();
  q[a + 2] = r.y();
  q[a + 3] = r.z();
}

PoseSample pose_at(std::int64_t t_us, double u) {
  // u = 0: rest at the origin; u = 1: walked 1 m along +X, the right elbow
  // bent 1 rad, the left upper arm turned 1 rad about +X, the body turned 1 rad about +Z.
  PoseSample s;
  s.t_us = t_us;
  s.qpos = humanoid().qpos0;
  s.qpos[0] += u;
  s.qpos[adr(Bone::RightLowerArm)] = u;
  set_quat(s.qpos, adr(Bone::LeftUpperArm), sim::Quat(Eigen::AngleAxisd(u, sim::Vec3::UnitX())));
  set_quat(s.qpos, 3, sim::Quat(Eigen::AngleAxisd(u, sim::Vec3::UnitZ())));
  return s;
}

}  // namespace

TEST_CASE("pose buffer: the pose between two samples is interpolated at the tick's time minus the delay") {
  PoseBufferConfig c;
  c.delay_s = 0.03;
  PoseBuffer b(humanoid(), c);
  b.push(pose_at(1'000'000, 0.0));
  b.push(pose_at(1'100'000, 1.0));
  Qpos out{};
  // Tick at 1.08 s: the buffer shows 1.05 s, halfway between the samples at 1.0 and 1.1 s.
  CHECK(b.sample(1'080'000, out) == PoseState::live);
  CHECK(out[0] == doctest::Approx(humanoid().qpos0[0] + 0.5));
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(0.5));
  // Slerp of a turn about one axis is half the angle about that axis (closed form).
  const Eigen::AngleAxisd arm(quat(out, adr(Bone::LeftUpperArm)));
  CHECK(arm.angle() == doctest::Approx(0.5));
  CHECK(arm.axis().x() == doctest::Approx(1.0));
  const Eigen::AngleAxisd root(quat(out, 3));
  CHECK(root.angle() == doctest::Approx(0.5));
  CHECK(root.axis().z() == doctest::Approx(1.0));
}

TEST_CASE("pose buffer: a stopped stream is held, eased to a neutral where it stood, then comes back blended") {
  PoseBufferConfig c;  // delay 30 ms, hold 250 ms, ease 500 ms, recover 200 ms
  PoseBuffer b(humanoid(), c);
  Qpos out{};
  CHECK(b.sample(0, out) == PoseState::none);  // nothing yet: neutral at the origin
  b.push(pose_at(1'000'000, 0.0));
  b.push(pose_at(1'100'000, 1.0));
  // Held: the newest pose, until 250 ms after it (at the delayed time).
  CHECK(b.sample(1'300'000, out) == PoseState::held);
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(1.0));
  // Easing halfway: the elbow halfway to the neutral's straight arm.
  CHECK(b.sample(1'100'000 + 30'000 + 250'000 + 250'000, out) == PoseState::easing);
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(0.5));
  // Neutral: where it stood and faced, upright, elbows straight, arms by the sides.
  CHECK(b.sample(2'000'000, out) == PoseState::neutral);
  CHECK(out[0] == doctest::Approx(humanoid().qpos0[0] + 1.0));
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(0.0));
  const Eigen::AngleAxisd heading(quat(out, 3));
  CHECK(heading.angle() == doctest::Approx(1.0));
  const sim::Vec3 left_arm_dir = quat(out, adr(Bone::LeftUpperArm)) * sim::Vec3::UnitY();
  CHECK(left_arm_dir.z() < -0.9);  // hanging down
  // The stream comes back: blended from the neutral over 200 ms.
  b.push(pose_at(2'000'000, 0.0));
  b.push(pose_at(2'010'000, 0.0));
  CHECK(b.sample(2'040'000, out) == PoseState::recovering);
  CHECK(out[0] == doctest::Approx(humanoid().qpos0[0] + 1.0));  // starts where it was shown
  b.push(pose_at(2'300'000, 0.0));
  CHECK(b.sample(2'140'000, out) == PoseState::recovering);
  CHECK(out[0] == doctest::Approx(humanoid().qpos0[0] + 0.5));
  CHECK(b.sample(2'250'000, out) == PoseState::live);
  CHECK(out[0] == doctest::Approx(humanoid().qpos0[0]));
}

TEST_CASE("pose buffer: older samples are dropped and counted, a full ring keeps the newest") {
  PoseBuffer b(humanoid(), PoseBufferConfig{});
  b.push(pose_at(1000, 0.0));
  b.push(pose_at(500, 0.0));
  b.push(pose_at(1000, 0.0));
  CHECK(b.dropped_out_of_order() == 2);
  for (std::int64_t k = 1; k <= 200; ++k) b.push(pose_at(1000 + k * 1000, 0.0));
  CHECK(b.size() == PoseBuffer::kCapacity);
  CHECK(b.newest_us() == 201'000);
  CHECK(b.received() == 201);
  PoseBufferConfig bad;
  bad.delay_s = -1.0;
  CHECK(validate(bad).find("tracker.delay_ms = -1000") != std::string::npos);
}

TEST_CASE("pose buffer: a cut (a clip starting over) steps instead of sweeping across the gap") {
  PoseBufferConfig c;
  c.delay_s = 0.0;
  PoseBuffer b(humanoid(), c);
  b.push(pose_at(1'000'000, 1.0));
  PoseSample next = pose_at(1'010'000, 0.0);
  next.cut = true;
  b.push(next);
  Qpos out{};
  CHECK(b.sample(1'005'000, out) == PoseState::live);
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(1.0));  // still the old take
  CHECK(b.sample(1'010'000, out) == PoseState::live);
  CHECK(out[adr(Bone::RightLowerArm)] == doctest::Approx(0.0));  // the new one, whole
}
