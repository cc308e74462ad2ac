// VmcSender -> loopback -> VmcReceiver (performer mode) -> BodyRetarget: the
// humanoid's pose comes back as the same joint rotations, the sender's
// skeleton is the humanoid's, and the counters agree on both sides.
#include <doctest/doctest.h>

#include <cmath>

#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/host/vmc/receiver.hpp"
#include "tonus/host/vmc/sender.hpp"
#include "vmc_fixtures.hpp"

using namespace tonus;
using sim::Quat;
using sim::Vec3;

namespace {

struct Loopback {
  vmc::VmcReceiver receiver;
  vmc::VmcSender sender;
  std::vector<vmc::ReceivedFrame> frames;

  explicit Loopback(bool bundle = true)
      : receiver([] {
          vmc::ReceiverOptions o;
          o.port = 0;
          return o;
        }()),
        sender([&] {
          vmc::SenderOptions o;
          o.port = receiver.port();
          o.bundle = bundle;
          return o;
        }()) {
    REQUIRE_MESSAGE(receiver.ok(), receiver.error());
    REQUIRE_MESSAGE(sender.ok(), sender.error());
    REQUIRE(receiver.port() > 0);
    receiver.set_handler([this](const vmc::ReceivedFrame& f) { frames.push_back(f); });
  }

  // Sends one frame and pumps until every one of its messages is decoded.
  void send(const vmc::VmcPose& pose, double t) {
    const std::uint64_t before = receiver.counters().messages;
    const std::uint64_t sent_before = sender.counters().messages;
    REQUIRE(sender.send(pose, t, {}, nullptr));
    const std::uint64_t sent = sender.counters().messages - sent_before;
    REQUIRE(vmc::test::pump(receiver, [&] { return receiver.counters().messages >= before + sent; }));
  }
};

// The union of the frames since `from`: the latest value of each bone.
reference::BodySample merged(const std::vector<vmc::ReceivedFrame>& frames, std::size_t from) {
  reference::BodySample s;
  for (std::size_t k = from; k < frames.size(); ++k) {
    const reference::BodySample& f = frames[k].body;
    for (std::size_t i = 0; i < sim::kBoneCount; ++i) {
      if (!f.present[i]) continue;
      s.present[i] = true;
      s.local[i] = f.local[i];
    }
    if (f.root_present) {
      s.root_present = true;
      s.root_position = f.root_position;
      s.root_rotation = f.root_rotation;
    }
  }
  return s;
}

}  // namespace

TEST_CASE("vmc round trip: the pose, the skeleton and the retargeted joints come back") {
  const sim::Model& m = vmc::test::humanoid();
  Loopback loop;
  const Vec3 root_pos(0.4, -0.3, 0.91);
  const Quat root_rot(Eigen::AngleAxisd(-2.2, Vec3(0.05, 0.1, 1.0).normalized()));
  const std::vector<double> q = vmc::test::lively_qpos(root_pos, root_rot);
  vmc::VmcPose pose;
  REQUIRE(vmc::pose_from_qpos(m, q, pose));

  for (int k = 0; k < 4; ++k) loop.send(pose, 0.1 * k);
  const std::size_t per_send = loop.sender.counters().bundles / 4;  // one frame per bundle
  REQUIRE(loop.frames.size() == 4 * per_send);
  const std::size_t last_from = loop.frames.size() - per_send;
  const vmc::ReceivedFrame& last = loop.frames.back();
  CHECK(last.mode == vmc::ReceiverMode::performer);
  REQUIRE(last.sender_time_s.has_value());
  CHECK(*last.sender_time_s == doctest::Approx(0.3));
  CHECK(last.arrival_us > 0);
  CHECK(loop.receiver.sender().ok_seen);
  CHECK(loop.receiver.sender().loaded == 1);
  CHECK(loop.receiver.sender().calibration_state == 3);
  CHECK(loop.receiver.sender().tracking_status == 1);

  // Every bone, its local rotation as the humanoid's joint (float precision).
  const reference::BodySample s = merged(loop.frames, last_from);
  double worst = 0.0;
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    CAPTURE(sim::kBones[i].name);
    REQUIRE(s.present[i]);
    const sim::Body& b = m.bodies[i];
    const auto a = static_cast<std::size_t>(b.qpos_adr);
    Quat expect = Quat::Identity();
    if (b.joint == sim::JointType::ball) expect = Quat(q[a], q[a + 1], q[a + 2], q[a + 3]);
    if (b.joint == sim::JointType::hinge) expect = Quat(Eigen::AngleAxisd(q[a], b.hinge_axis));
    worst = std::max(worst, s.local[i].angularDistance(expect));
  }
  REQUIRE(s.root_present);
  CHECK((s.root_position - root_pos).norm() < 1e-6);
  CHECK(s.root_rotation.angularDistance(root_rot) < 1e-6);
  MESSAGE("largest joint rotation error through VMC: " << worst << " rad");
  CHECK(worst < 1e-6);

  // The sender's skeleton: the humanoid's offsets; the retarget rebuilds the joints.
  REQUIRE(last.skeleton_ready);
  REQUIRE(loop.receiver.skeleton().has_value());
  const reference::SourceSkeleton& k = *loop.receiver.skeleton();
  const reference::SourceSkeleton own = reference::skeleton_of(m);
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    CHECK(k.present[i]);
    CHECK((k.offset[i] - own.offset[i]).norm() < 1e-6);
    CHECK(k.rest_rotation[i].angularDistance(Quat::Identity()) < 1e-12);
  }
  MESSAGE("hips rest height: learnt " << k.offset[0].z() << " m, the humanoid's " << own.offset[0].z() << " m");
  CHECK(std::abs(k.offset[0].z() - own.offset[0].z()) < 0.1);
  const reference::BodyRetargetBuild built = reference::BodyRetarget::create(m, k);
  REQUIRE_MESSAGE(built.ok(), built.error);
  CHECK(built.retarget->scale() == doctest::Approx(1.0).epsilon(1e-5));
  reference::BodyRetargetState state;
  std::array<double, sim::kMaxQpos> out{};
  const reference::BodyStatus st = built.retarget->solve(s, state, out);
  REQUIRE(st.written);
  CHECK(st.input_valid());
  double joint_err = 0.0;
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    const sim::Body& b = m.bodies[i];
    const auto a = static_cast<std::size_t>(b.qpos_adr);
    if (b.joint == sim::JointType::ball) {
      joint_err = std::max(
          joint_err,
          Quat(out[a], out[a + 1], out[a + 2], out[a + 3]).angularDistance(Quat(q[a], q[a + 1], q[a + 2], q[a + 3])));
    } else if (b.joint == sim::JointType::hinge) {
      joint_err = std::max(joint_err, std::abs(out[a] - q[a]));
    }
  }
  MESSAGE("sent qpos -> VMC -> BodyRetarget: largest joint error " << joint_err << " rad, root height offset "
                                                                   << out[2] - q[2] << " m");
  CHECK(joint_err < 1e-4);
  CHECK(std::abs(out[0] - q[0]) < 1e-4);
  CHECK(std::abs(out[1] - q[1]) < 1e-4);
  CHECK(std::abs(out[2] - q[2]) < 0.1);

  // Both sides counted the same traffic; the receiver ignored only tonus's own messages.
  CHECK(loop.receiver.counters().bundles == loop.sender.counters().bundles);
  CHECK(loop.receiver.counters().messages == loop.sender.counters().messages);
  CHECK(loop.receiver.counters().ignored == 4);  // /tonus/Object/Clear, once per frame
  CHECK(loop.receiver.counters().malformed == 0);
  CHECK(loop.receiver.counters().frames == loop.frames.size());
}

TEST_CASE("vmc round trip: plain messages make one frame per pose message") {
  const sim::Model& m = vmc::test::humanoid();
  Loopback loop(false);
  vmc::VmcPose pose;
  REQUIRE(vmc::pose_from_qpos(m, vmc::test::lively_qpos(Vec3(0, 0, 0.9), Quat::Identity()), pose));
  loop.send(pose, 1.0);
  CHECK(loop.receiver.counters().bundles == 0);
  CHECK(loop.frames.size() == 1 + sim::kBoneCount);  // Root, then each bone
  const reference::BodySample s = merged(loop.frames, 0);
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) CHECK(s.present[i]);
}

TEST_CASE("vmc receiver: a port in use is a clear error, not a crash") {
  vmc::ReceiverOptions o;
  o.port = 0;
  vmc::VmcReceiver first(o);
  REQUIRE(first.ok());
  o.port = first.port();
  vmc::VmcReceiver second(o);
  CHECK_FALSE(second.ok());
  MESSAGE(second.error());
  CHECK(second.error().find("Address already in use") != std::string::npos);
  CHECK(second.error().find(std::to_string(first.port())) != std::string::npos);
  CHECK(second.receive(5) == 0);  // usable as a dead receiver

  vmc::ReceiverOptions bad;
  bad.address = "localhost";
  CHECK(vmc::VmcReceiver(bad).error().find("numeric") != std::string::npos);
  bad.address = "127.0.0.1";
  bad.port = 70000;
  CHECK_FALSE(vmc::VmcReceiver(bad).ok());
  // IPv6 loopback binds too.
  vmc::ReceiverOptions v6;
  v6.address = "::1";
  v6.port = 0;
  const vmc::VmcReceiver r6(v6);
  CHECK_MESSAGE((r6.ok() || r6.error().find("Address family") != std::string::npos ||
                 r6.error().find("Cannot assign") != std::string::npos),
                r6.error());
}
