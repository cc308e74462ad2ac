// VmcSender read back by a plain UDP socket and liblo's message decoder (not
// the receiver): bundle sizes, order, the full bone set, normalised
// quaternions, objects, stiffness, plain messages, counters, bad options.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "tonus/host/vmc/sender.hpp"
#include "tonus/sim/human_bones.hpp"
#include "vmc_fixtures.hpp"

using namespace tonus;
using sim::Quat;
using sim::Vec3;

namespace {

vmc::VmcPose lively_pose() {
  vmc::VmcPose pose;
  const std::vector<double> q =
      vmc::test::lively_qpos(Vec3(0.1, 0.2, 0.93), Quat(Eigen::AngleAxisd(0.7, Vec3::UnitZ())));
  REQUIRE(vmc::pose_from_qpos(vmc::test::humanoid(), q, pose));
  return pose;
}

std::size_t count(const std::vector<vmc::test::OscMessage>& ms, const std::string& path) {
  return static_cast<std::size_t>(std::count_if(ms.begin(), ms.end(), [&](const auto& m) { return m.path == path; }));
}

void check_frame(const std::vector<vmc::test::OscMessage>& ms, const vmc::VmcPose& pose) {
  REQUIRE(ms.size() >= 2);
  // The first bundle opens with OK and T.
  CHECK(ms[0].path == "/VMC/Ext/OK");
  CHECK(ms[0].types == "iiii");
  CHECK(ms[0].numbers == std::vector<double>{1, 3, 0, 1});
  CHECK(ms[1].path == "/VMC/Ext/T");
  CHECK(ms[1].types == "f");
  CHECK(ms[0].datagram == 0);
  if (ms[0].in_bundle) CHECK(ms[1].datagram == 0);
  CHECK(count(ms, "/VMC/Ext/Root/Pos") == 1);
  std::set<std::string> bones;
  for (const vmc::test::OscMessage& m : ms) {
    if (m.path != "/VMC/Ext/Bone/Pos" && m.path != "/VMC/Ext/Root/Pos") continue;
    REQUIRE(m.types == "sfffffff");
    REQUIRE(m.numbers.size() == 7);
    const double n = std::sqrt(m.numbers[3] * m.numbers[3] + m.numbers[4] * m.numbers[4] + m.numbers[5] * m.numbers[5] +
                               m.numbers[6] * m.numbers[6]);
    CHECK(std::abs(n - 1.0) < 1e-6);
    if (m.path == "/VMC/Ext/Root/Pos") {
      CHECK(m.strings[0] == "root");
      continue;
    }
    CHECK(bones.insert(m.strings[0]).second);  // each once
    const std::optional<sim::Bone> b = sim::bone_from_name(m.strings[0]);
    REQUIRE(b);
    const vmc::UnityTransform& t = pose.bone[sim::index(*b)];
    CHECK(std::abs(m.numbers[0] - t.pos_m.x()) < 1e-6);
    CHECK(std::abs(m.numbers[1] - t.pos_m.y()) < 1e-6);
    CHECK(std::abs(m.numbers[2] - t.pos_m.z()) < 1e-6);
    CHECK(std::abs(m.numbers[3] - t.rot.x()) < 1e-6);
    CHECK(std::abs(m.numbers[4] - t.rot.y()) < 1e-6);
    CHECK(std::abs(m.numbers[5] - t.rot.z()) < 1e-6);
    CHECK(std::abs(m.numbers[6] - t.rot.w()) < 1e-6);
  }
  CHECK(bones.size() == sim::kBoneCount);
}

}  // namespace

TEST_CASE("vmc sender: bundles within 1500 bytes, the full bone set, OK and T first") {
  vmc::test::UdpSocket sink;
  vmc::SenderOptions o;
  o.port = sink.port();
  vmc::VmcSender sender(o);
  REQUIRE_MESSAGE(sender.ok(), sender.error());
  const vmc::VmcPose pose = lively_pose();
  REQUIRE(sender.send(pose, 12.5, {}, nullptr));
  const auto datagrams = sink.receive_all();
  REQUIRE(datagrams.size() >= 2);  // 21 bones do not fit one 1500-byte bundle
  std::size_t bytes = 0;
  for (const auto& d : datagrams) {
    CHECK(d.size() <= 1500);
    CHECK(std::string(reinterpret_cast<const char*>(d.data())) == "#bundle");
    bytes += d.size();
  }
  MESSAGE(datagrams.size() << " bundles, " << bytes << " bytes per frame");
  const auto ms = vmc::test::decode_all(datagrams);
  check_frame(ms, pose);
  CHECK(ms[1].numbers[0] == doctest::Approx(12.5));
  CHECK(count(ms, "/tonus/Object/Clear") == 1);
  CHECK(count(ms, "/tonus/Object/Pos") == 0);
  CHECK(count(ms, "/tonus/Stiffness") == 0);
  CHECK(sender.counters().bundles == datagrams.size());
  CHECK(sender.counters().messages == ms.size());
  CHECK(sender.counters().bytes == bytes);
  CHECK(sender.counters().frames == 1);
  CHECK(sender.counters().send_errors == 0);
}

TEST_CASE("vmc sender: objects and stiffness, a small datagram limit splits further") {
  vmc::test::UdpSocket sink;
  vmc::SenderOptions o;
  o.port = sink.port();
  o.max_datagram_bytes = 300;
  vmc::VmcSender sender(o);
  REQUIRE(sender.ok());
  const vmc::VmcPose pose = lively_pose();
  const std::array<vmc::VmcObject, 2> objects{
      vmc::object_to_vmc(3, vmc::ObjectKind::ball, 0.22, Vec3(1.0, 0.0, 1.3), Quat::Identity()),
      vmc::object_to_vmc(9, vmc::ObjectKind::cube, 0.08, Vec3(0.3, -0.4, 1.1), Quat(0.9, 0.1, 0.2, 0.3))};
  const std::array<float, 4> stiffness{0.25F, 1.5F, -0.5F, 0.75F};
  REQUIRE(sender.send(pose, 1.0, objects, &stiffness));
  const auto datagrams = sink.receive_all();
  for (const auto& d : datagrams) CHECK(d.size() <= 300);
  CHECK(datagrams.size() >= 6);
  const auto ms = vmc::test::decode_all(datagrams);
  check_frame(ms, pose);
  CHECK(count(ms, "/tonus/Object/Clear") == 0);
  REQUIRE(count(ms, "/tonus/Object/Pos") == 2);
  for (const auto& m : ms) {
    if (m.path == "/tonus/Object/Pos") {
      CHECK(m.types == "isffffffff");
      const bool ball = m.numbers[0] == 3.0;
      CHECK(m.strings[0] == (ball ? "ball" : "cube"));
      CHECK(m.numbers[1] == doctest::Approx(ball ? 0.22 : 0.08));
      if (ball) {  // internal (1, 0, 1.3) -> Unity (0, 1.3, 1)
        CHECK(m.numbers[2] == doctest::Approx(0.0));
        CHECK(m.numbers[3] == doctest::Approx(1.3));
        CHECK(m.numbers[4] == doctest::Approx(1.0));
      }
    }
    if (m.path == "/tonus/Stiffness") {
      CHECK(m.types == "ffff");
      CHECK(m.numbers == std::vector<double>{0.25, 1.0, 0.0, 0.75});  // clamped into 0..1
    }
  }
  CHECK(count(ms, "/tonus/Stiffness") == 1);
}

TEST_CASE("vmc sender: plain messages when bundles are off") {
  vmc::test::UdpSocket sink;
  vmc::SenderOptions o;
  o.port = sink.port();
  o.bundle = false;
  vmc::VmcSender sender(o);
  REQUIRE(sender.ok());
  const vmc::VmcPose pose = lively_pose();
  const std::array<float, 4> stiffness{0.1F, 0.2F, 0.3F, 0.4F};
  REQUIRE(sender.send(pose, 2.0, {}, &stiffness));
  const auto datagrams = sink.receive_all();
  const auto ms = vmc::test::decode_all(datagrams);
  CHECK(datagrams.size() == ms.size());
  for (const auto& m : ms) CHECK_FALSE(m.in_bundle);
  check_frame(ms, pose);
  CHECK(ms.size() == 2 + 1 + sim::kBoneCount + 1 + 1);  // OK, T, Root, bones, Clear, Stiffness
  CHECK(sender.counters().bundles == 0);
  CHECK(sender.counters().messages == ms.size());
}

TEST_CASE("vmc sender: bad options and non-finite poses") {
  vmc::SenderOptions o;
  o.port = 0;
  CHECK_FALSE(vmc::VmcSender(o).ok());
  o.port = 70000;
  CHECK_FALSE(vmc::VmcSender(o).ok());
  o.port = 39539;
  o.max_datagram_bytes = 100;
  CHECK_FALSE(vmc::VmcSender(o).ok());
  o.max_datagram_bytes = 1500;
  o.host = "";
  CHECK_FALSE(vmc::VmcSender(o).error().empty());

  vmc::test::UdpSocket sink;
  vmc::SenderOptions good;
  good.port = sink.port();
  vmc::VmcSender sender(good);
  vmc::VmcPose pose = lively_pose();
  pose.bone[4].pos_m.y() = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(sender.send(pose, 0.0, {}, nullptr));
  CHECK(sender.counters().rejected == 1);
  pose = lively_pose();
  std::array<vmc::VmcObject, 1> bad{vmc::VmcObject{}};
  bad[0].size_m = std::numeric_limits<double>::infinity();
  CHECK_FALSE(sender.send(pose, 0.0, bad, nullptr));
  CHECK(sender.counters().rejected == 2);
  CHECK(sender.counters().bundles == 0);
  // NaN stiffness: the frame goes, the stiffness message does not.
  const std::array<float, 4> nan_stiffness{0.5F, std::numeric_limits<float>::quiet_NaN(), 0.5F, 0.5F};
  CHECK(sender.send(pose, 0.0, {}, &nan_stiffness));
  const auto ms = vmc::test::decode_all(sink.receive_all());
  CHECK(count(ms, "/tonus/Stiffness") == 0);
  CHECK(count(ms, "/VMC/Ext/Bone/Pos") == sim::kBoneCount);
}
