// Tracker mode: Hmd/Con/Tra messages to a TrackerFrame in the internal frame;
// serials by the config map, else by the heuristic (head first; controllers
// by side of the head's facing; trackers by height then side), stable once
// assigned.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>

#include "tonus/host/vmc/receiver.hpp"
#include "tonus/host/vmc/unity_frame.hpp"
#include "vmc_fixtures.hpp"

using namespace tonus;
using reference::Tracker;
using sim::Quat;
using sim::Vec3;
using Bytes = std::vector<unsigned char>;

namespace {

// (serial)(Unity position)(Unity rotation x y z w).
Bytes tracker(const char* address, const std::string& serial, const Vec3& unity_pos,
              const Quat& unity_rot = Quat::Identity()) {
  return vmc::test::osc_message(
      address, "sfffffff",
      {unity_pos.x(), unity_pos.y(), unity_pos.z(), unity_rot.x(), unity_rot.y(), unity_rot.z(), unity_rot.w()},
      {serial});
}

struct Target {
  vmc::VmcReceiver receiver;
  vmc::test::UdpSocket socket;
  std::vector<vmc::ReceivedFrame> frames;

  explicit Target(std::vector<std::pair<std::string, Tracker>> map = {})
      : receiver([&] {
          vmc::ReceiverOptions o;
          o.port = 0;
          o.mode = vmc::ReceiverMode::tracker;
          o.serial_map = std::move(map);
          return o;
        }()) {
    REQUIRE(receiver.ok());
    receiver.set_handler([this](const vmc::ReceivedFrame& f) { frames.push_back(f); });
  }

  // One bundle; returns its frame (REQUIREs one).
  const vmc::ReceivedFrame& send(const std::vector<Bytes>& messages) {
    const std::size_t before = frames.size();
    const std::uint64_t datagrams = receiver.counters().datagrams;
    socket.send_to(receiver.port(), vmc::test::osc_bundle(messages));
    REQUIRE(vmc::test::pump(receiver, [&] { return receiver.counters().datagrams > datagrams; }));
    REQUIRE(frames.size() == before + 1);
    return frames.back();
  }
};

// A standing performer in Unity: head 1.6 m up facing +z; the avatar's left is -x.
std::vector<Bytes> six_points(const std::string& left_hand, const std::string& right_hand, const std::string& waist,
                              const std::string& left_foot, const std::string& right_foot, double yaw_unity = 0.0) {
  const Quat yaw(Eigen::AngleAxisd(yaw_unity, Vec3::UnitY()));
  const auto at = [&](double x, double y, double z) { return Vec3(yaw * Vec3(x, y, z)); };
  return {
      tracker("/VMC/Ext/Hmd/Pos", "HMD", at(0, 1.6, 0), yaw),
      tracker("/VMC/Ext/Con/Pos", left_hand, at(-0.35, 1.1, 0.2)),
      tracker("/VMC/Ext/Con/Pos", right_hand, at(0.35, 1.1, 0.2)),
      tracker("/VMC/Ext/Tra/Pos", waist, at(0.0, 0.95, -0.05)),
      tracker("/VMC/Ext/Tra/Pos", left_foot, at(-0.12, 0.08, 0.0)),
      tracker("/VMC/Ext/Tra/Pos", right_foot, at(0.12, 0.08, 0.0)),
  };
}

}  // namespace

TEST_CASE("vmc tracker mode: the heuristic assigns six points, converted to the internal frame") {
  Target t;
  const vmc::ReceivedFrame& f = t.send(six_points("C1", "C2", "T1", "T2", "T3"));
  CHECK(f.mode == vmc::ReceiverMode::tracker);
  for (const Tracker k : {Tracker::head, Tracker::left_hand, Tracker::right_hand, Tracker::waist, Tracker::left_foot,
                          Tracker::right_foot}) {
    CAPTURE(reference::tracker_name(k));
    CHECK(f.trackers[k].valid);
  }
  CHECK_FALSE(f.trackers[Tracker::left_elbow].valid);
  // Unity (0, 1.6, 0) -> internal (0, 0, 1.6); the left controller at Unity x = -0.35 -> internal y = +0.35.
  CHECK((f.trackers[Tracker::head].pos_m - Vec3(0, 0, 1.6)).norm() < 1e-6);
  CHECK((f.trackers[Tracker::left_hand].pos_m - Vec3(0.2, 0.35, 1.1)).norm() < 1e-6);
  CHECK((f.trackers[Tracker::right_hand].pos_m - Vec3(0.2, -0.35, 1.1)).norm() < 1e-6);
  CHECK((f.trackers[Tracker::waist].pos_m - Vec3(-0.05, 0, 0.95)).norm() < 1e-6);
  CHECK(f.trackers[Tracker::left_foot].pos_m.y() > 0.0);
  CHECK(f.trackers.time_s == doctest::Approx(static_cast<double>(f.arrival_us) * 1e-6));
  const auto& a = t.receiver.tracker_assignments();
  CHECK(a.size() == 6);
  CHECK(t.receiver.counters().unassigned == 0);

  // Stable: the hands crossed and the feet swapped keep their roles.
  const vmc::ReceivedFrame& g = t.send(six_points("C2", "C1", "T1", "T3", "T2"));
  CHECK(g.trackers[Tracker::left_hand].pos_m.y() < 0.0);  // C1 is the left hand, now on the right
  CHECK(g.trackers[Tracker::left_foot].pos_m.y() < 0.0);
  CHECK(t.receiver.tracker_assignments().size() == 6);
}

TEST_CASE("vmc tracker mode: sides follow the head's facing") {
  Target t;
  // Turned to face Unity -z: the avatar's left is now Unity +x.
  const vmc::ReceivedFrame& f = t.send(six_points("C1", "C2", "T1", "T2", "T3", std::numbers::pi));
  // six_points turns every position with the head, so C1 (its left) is still the left hand.
  CHECK(f.trackers[Tracker::left_hand].valid);
  const auto& a = t.receiver.tracker_assignments();
  const auto role = [&](const std::string& s) {
    for (const auto& [serial, r] : a) {
      if (serial == s) return r;
    }
    FAIL("unassigned " << s);
    return Tracker::head;
  };
  CHECK(role("C1") == Tracker::left_hand);
  CHECK(role("C2") == Tracker::right_hand);
  CHECK(role("T1") == Tracker::waist);
  CHECK(role("T2") == Tracker::left_foot);
  CHECK(role("T3") == Tracker::right_foot);
  // The internal left hand is at +y relative to the head turned 180 degrees: world -y.
  CHECK(f.trackers[Tracker::left_hand].pos_m.y() < 0.0);
}

TEST_CASE("vmc tracker mode: controllers before the head wait, the map wins and reserves its roles") {
  Target t({{"MAPPED-R", Tracker::right_hand}});
  // No head yet: the controller cannot be placed.
  const std::uint64_t before = t.receiver.counters().datagrams;
  t.socket.send_to(t.receiver.port(), vmc::test::osc_bundle({tracker("/VMC/Ext/Con/Pos", "C9", Vec3(0.35, 1.1, 0.2))}));
  REQUIRE(vmc::test::pump(t.receiver, [&] { return t.receiver.counters().datagrams > before; }));
  CHECK(t.receiver.counters().unassigned == 1);
  CHECK(t.frames.empty());

  // With the head: C9 is on the right, but the map reserves the right hand: C9 becomes the left.
  const vmc::ReceivedFrame& f = t.send({tracker("/VMC/Ext/Hmd/Pos", "HMD", Vec3(0, 1.6, 0)),
                                        tracker("/VMC/Ext/Con/Pos", "C9", Vec3(0.35, 1.1, 0.2)),
                                        tracker("/VMC/Ext/Con/Pos", "MAPPED-R", Vec3(-0.35, 1.1, 0.2))});
  CHECK(f.trackers[Tracker::left_hand].valid);
  CHECK(f.trackers[Tracker::left_hand].pos_m.y() < 0.0);   // C9, on the right
  CHECK(f.trackers[Tracker::right_hand].pos_m.y() > 0.0);  // the mapped serial wherever it is
  // A third controller has no role left.
  const std::uint64_t unassigned = t.receiver.counters().unassigned;
  t.send({tracker("/VMC/Ext/Hmd/Pos", "HMD", Vec3(0, 1.6, 0)), tracker("/VMC/Ext/Con/Pos", "C10", Vec3(0.3, 1, 0))});
  CHECK(t.receiver.counters().unassigned == unassigned + 1);
}

TEST_CASE("vmc tracker mode: bad tracker messages, bones ignored") {
  Target t;
  const vmc::ReceivedFrame& f =
      t.send({tracker("/VMC/Ext/Hmd/Pos", "HMD", Vec3(0, 1.6, 0)), tracker("/VMC/Ext/Con/Pos", "", Vec3(0.3, 1, 0)),
              vmc::test::osc_message("/VMC/Ext/Tra/Pos", "sfff", {0, 1, 0}, {"T"}),
              vmc::test::osc_message("/VMC/Ext/Bone/Pos", "sfffffff", {0, 0, 0, 0, 0, 0, 1}, {"Hips"})});
  CHECK(f.trackers[Tracker::head].valid);
  CHECK(t.receiver.counters().malformed == 2);  // the empty serial, the short message
  CHECK(t.receiver.counters().ignored == 1);    // Bone/Pos is a performer-mode address
}
