// VMC over OSC (host/vmc's receiver, both modes): any datagram is decoded
// without a crash or an exception; every pose handed out is finite with unit
// quaternions (a sender's garbage never reaches the reference); the counters
// account for every datagram.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_check.hpp"
#include "tonus/host/vmc/receiver.hpp"

using namespace tonus;

namespace {

bool unit(const sim::Quat& q) { return std::isfinite(q.norm()) && std::abs(q.norm() - 1.0) < 1e-6; }
bool finite(const sim::Vec3& v) { return v.allFinite(); }

void check(const vmc::ReceivedFrame& f) {
  if (f.mode == vmc::ReceiverMode::performer) {
    for (std::size_t b = 0; b < f.body.present.size(); ++b) {
      if (f.body.present[b]) TONUS_FUZZ_CHECK(unit(f.body.local[b]));
    }
    if (f.body.root_present) {
      TONUS_FUZZ_CHECK(finite(f.body.root_position));
      TONUS_FUZZ_CHECK(unit(f.body.root_rotation));
    }
  } else {
    for (const reference::TrackerPose& p : f.trackers.pose) {
      if (!p.valid) continue;
      TONUS_FUZZ_CHECK(finite(p.pos_m));
      TONUS_FUZZ_CHECK(unit(p.rot));
    }
  }
  if (f.sender_time_s) TONUS_FUZZ_CHECK(std::isfinite(*f.sender_time_s));
}

vmc::ReceiverOptions options(vmc::ReceiverMode mode) {
  vmc::ReceiverOptions o;
  o.port = 0;
  o.mode = mode;
  o.skeleton_frames = 1;  // learn a skeleton from the first complete frame: deeper paths sooner
  return o;
}

vmc::VmcReceiver& receiver(vmc::ReceiverMode mode) {
  static vmc::VmcReceiver performer(options(vmc::ReceiverMode::performer));
  static vmc::VmcReceiver tracker(options(vmc::ReceiverMode::tracker));
  return mode == vmc::ReceiverMode::performer ? performer : tracker;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static std::int64_t arrival_us = 0;
  for (const vmc::ReceiverMode mode : {vmc::ReceiverMode::performer, vmc::ReceiverMode::tracker}) {
    vmc::VmcReceiver& r = receiver(mode);
    r.set_handler(check);
    const std::uint64_t before = r.counters().datagrams;
    r.decode(data, size, arrival_us += 1000);
    TONUS_FUZZ_CHECK(r.counters().datagrams == before + 1);
    TONUS_FUZZ_CHECK(r.counters().handler_exceptions == 0);
  }
  return 0;
}
