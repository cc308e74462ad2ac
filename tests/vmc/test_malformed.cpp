// Hand-made datagrams through a plain UDP socket: every kind of bad input is
// counted (malformed or ignored), nothing crashes, and the receiver keeps
// decoding good frames after it.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>

#include "tonus/host/vmc/receiver.hpp"
#include "tonus/host/vmc/unity_frame.hpp"
#include "vmc_fixtures.hpp"

using namespace tonus;
using sim::Quat;
using sim::Vec3;
using Bytes = std::vector<unsigned char>;

namespace {

Bytes bone(const std::string& name, const std::vector<double>& seven) {
  return vmc::test::osc_message("/VMC/Ext/Bone/Pos", "sfffffff", seven, {name});
}

struct Target {
  vmc::VmcReceiver receiver;
  vmc::test::UdpSocket socket;
  std::vector<vmc::ReceivedFrame> frames;

  Target()
      : receiver([] {
          vmc::ReceiverOptions o;
          o.port = 0;
          return o;
        }()) {
    REQUIRE(receiver.ok());
    receiver.set_handler([this](const vmc::ReceivedFrame& f) { frames.push_back(f); });
  }

  // Sends and pumps until the receiver has seen the datagram.
  void send(const Bytes& d) {
    const std::uint64_t before = receiver.counters().datagrams;
    socket.send_to(receiver.port(), d);
    REQUIRE(vmc::test::pump(receiver, [&] { return receiver.counters().datagrams > before; }));
  }
};

}  // namespace

TEST_CASE("vmc receiver: malformed datagrams are counted, unknown addresses ignored, decoding goes on") {
  Target t;
  const double h = std::sqrt(0.5);
  const std::vector<double> good{0.0, 0.1, 0.0, 0.0, 0.0, -h, h};
  const Bytes valid = bone("LeftUpperArm", good);

  struct Case {
    const char* what;
    Bytes datagram;
    std::uint64_t malformed;
    std::uint64_t ignored;
  };
  Bytes truncated(valid.begin(), valid.end() - 8);  // two floats short, still 4-byte aligned
  Bytes odd = valid;
  odd.push_back(0);  // not a multiple of 4
  Bytes bad_bundle = vmc::test::osc_bundle({valid, valid});
  bad_bundle[16 + 3] = 0xF0;  // the first element's length beyond the datagram
  Bytes deep = valid;
  for (int k = 0; k < 10; ++k) deep = vmc::test::osc_bundle({deep});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Case> cases{
      {"truncated", truncated, 1, 0},
      {"size not a multiple of 4", odd, 1, 0},
      {"empty", {}, 1, 0},
      {"garbage", Bytes{'x', 'y', 'z', 'w', 1, 2, 3, 4}, 1, 0},
      {"no type tags", Bytes{'/', 'a', 0, 0}, 1, 0},
      {"wrong type tags", vmc::test::osc_message("/VMC/Ext/Bone/Pos", "siiiiiii", {0, 0, 0, 0, 0, 0, 1}, {"Hips"}), 1,
       0},
      {"too few arguments", vmc::test::osc_message("/VMC/Ext/Bone/Pos", "sffff", {0, 0, 0, 1}, {"Hips"}), 1, 0},
      {"NaN position", bone("Hips", {nan, 0, 0, 0, 0, 0, 1}), 1, 0},
      {"infinite quaternion", bone("Hips", {0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0, 1}), 1, 0},
      {"non-unit quaternion", bone("Hips", {0, 0, 0, 0, 0, 0, 2}), 1, 0},
      {"zero quaternion", bone("Hips", {0, 0, 0, 0, 0, 0, 0}), 1, 0},
      {"unknown bone", bone("LeftWing", good), 1, 0},
      {"empty bone name", bone("", good), 1, 0},
      {"root with wrong types", vmc::test::osc_message("/VMC/Ext/Root/Pos", "sfff", {0, 0, 0}, {"root"}), 1, 0},
      {"OK without an int", vmc::test::osc_message("/VMC/Ext/OK", "f", {1}, {}), 1, 0},
      {"T without a number", vmc::test::osc_message("/VMC/Ext/T", "s", {}, {"now"}), 1, 0},
      {"bundle element too long", bad_bundle, 1, 0},
      {"bundles nested 10 deep", deep, 1, 0},
      {"unknown address", vmc::test::osc_message("/foo/bar", "i", {1}, {}), 0, 1},
      {"blend shapes", vmc::test::osc_message("/VMC/Ext/Blend/Val", "sf", {0.5}, {"A"}), 0, 1},
      {"trackers in performer mode", vmc::test::osc_message("/VMC/Ext/Hmd/Pos", "sfffffff", good, {"HMD"}), 0, 1},
      {"a finger (valid, unused)", bone("LeftIndexProximal", good), 0, 0},
  };
  for (const Case& c : cases) {
    CAPTURE(c.what);
    const vmc::ReceiverCounters before = t.receiver.counters();
    t.send(c.datagram);
    CHECK(t.receiver.counters().malformed - before.malformed == c.malformed);
    CHECK(t.receiver.counters().ignored - before.ignored == c.ignored);
  }
  CHECK(t.frames.empty());  // none of them carried a usable pose

  // Still decoding: a bundle with extra trailing arguments (V2.1 scale and offset) and an UpperChest.
  std::vector<double> with_extras = good;
  for (int k = 0; k < 6; ++k) with_extras.push_back(1.0);
  const Bytes frame = vmc::test::osc_bundle({
      vmc::test::osc_message("/VMC/Ext/Root/Pos", "sfffffffffffff", {0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0}, {"root"}),
      vmc::test::osc_message("/VMC/Ext/Bone/Pos", "sfffffffffffff", with_extras, {"LeftUpperArm"}),
      bone("Hips", {0.0, 0.9, 0.0, 0.0, 0.0, 0.0, 1.0}),
      bone("UpperChest", {0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 1.0}),
  });
  const vmc::ReceiverCounters before = t.receiver.counters();
  t.send(frame);
  CHECK(t.receiver.counters().malformed == before.malformed);
  REQUIRE(t.frames.size() == 1);
  const reference::BodySample& s = t.frames[0].body;
  CHECK(s.present[sim::index(sim::Bone::LeftUpperArm)]);
  CHECK(s.present[sim::index(sim::Bone::Chest)]);  // UpperChest folded into the Chest
  CHECK_FALSE(s.present[sim::index(sim::Bone::Head)]);
  CHECK(s.root_present);
  CHECK((s.root_position - Vec3(0, 0, 0.9)).norm() < 1e-6);
  // Unity -90 degrees about z = internal +90 degrees about x (the left arm raised).
  CHECK(s.local[sim::index(sim::Bone::LeftUpperArm)].angularDistance(Quat(h, h, 0, 0)) < 1e-6);
}

TEST_CASE("vmc receiver: a bundle's good elements before a bad one still count") {
  Target t;
  const Bytes hips = bone("Hips", {0.0, 0.9, 0.0, 0.0, 0.0, 0.0, 1.0});
  Bytes b = vmc::test::osc_bundle({hips, Bytes{'/', 'x', 0, 0}});  // the second has no type tags
  t.send(b);
  CHECK(t.receiver.counters().malformed == 1);
  REQUIRE(t.frames.size() == 1);
  CHECK(t.frames[0].body.root_present);
}

TEST_CASE("vmc receiver: 3000 random and mutated datagrams, no crash, every one accounted for") {
  Target t;
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  const double h = std::sqrt(0.5);
  const Bytes good =
      vmc::test::osc_bundle({bone("Hips", {0, 0.9, 0, 0, 0, 0, 1}), bone("Spine", {0, 0.1, 0, 0, h, 0, h}),
                             vmc::test::osc_message("/VMC/Ext/T", "f", {3.0}, {})});
  std::uint64_t sent = 0;
  for (int k = 0; k < 3000; ++k) {
    Bytes d;
    if (k % 3 == 0) {
      d.resize(static_cast<std::size_t>(byte(rng)) * 4);
      for (unsigned char& c : d) c = static_cast<unsigned char>(byte(rng));
    } else {
      d = good;
      const int flips = 1 + k % 5;
      for (int f = 0; f < flips; ++f) {
        d[static_cast<std::size_t>(rng() % d.size())] = static_cast<unsigned char>(byte(rng));
      }
      if (k % 7 == 0) d.resize(d.size() - 4 * static_cast<std::size_t>(1 + rng() % 8));
    }
    t.socket.send_to(t.receiver.port(), d);
    ++sent;
    if (k % 50 == 49) {
      REQUIRE(vmc::test::pump(t.receiver, [&] { return t.receiver.counters().datagrams == sent; }));
    }
  }
  REQUIRE(vmc::test::pump(t.receiver, [&] { return t.receiver.counters().datagrams == sent; }));
  const vmc::ReceiverCounters& c = t.receiver.counters();
  MESSAGE("3000 datagrams: " << c.messages << " messages, " << c.malformed << " malformed, " << c.ignored
                             << " ignored, " << c.frames << " frames");
  CHECK(c.malformed > 500);
  for (const vmc::ReceivedFrame& f : t.frames) {
    CHECK(std::isfinite(f.body.root_position.norm()));
    for (const Quat& q : f.body.local) CHECK(std::abs(q.norm() - 1.0) < 1e-6);
  }
  // And a good frame after all of it.
  const std::size_t frames = t.frames.size();
  t.send(good);
  REQUIRE(t.frames.size() == frames + 1);
  CHECK((t.frames.back().body.root_position - Vec3(0, 0, 0.9)).norm() < 1e-6);
}
