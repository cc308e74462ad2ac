#include "tonus/host/daemon/config.hpp"

#include <cmath>

#include <fmt/format.h>

#include "tonus/host/viewer/vrm_file.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::daemon {
namespace {

bool in(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

std::string bad(std::string_view key, double v, std::string_view rule) {
  return fmt::format("{} = {}: {}", key, v, rule);
}

std::string validate_band(const BandConfig& b) {
  if (b.source == BandSource::sim) {
    if (b.sim_synthetic.empty() && b.sim_recording.empty()) {
      return "band.sim_synthetic = \"\": a scenario or band.sim_recording is needed";
    }
    if (!in(b.sim_seconds, 0.0, 1e6)) return bad("band.sim_seconds", b.sim_seconds, "must be 0..1000000");
  }
  if (b.source == BandSource::socket && b.sim_socket.empty()) {
    return "band.sim_socket = \"\": a socket path is needed for band.source = \"socket\"";
  }
  if (b.source == BandSource::can && (b.can_interface.empty() || b.can_interface.size() > 15)) {
    return fmt::format("band.can_interface = \"{}\": must be 1..15 characters", b.can_interface);
  }
  if (b.can_node < 0 || b.can_node > 15) return bad("band.can_node", b.can_node, "must be 0..15");
  if (b.can_id_base > 0x1FFFFFFFU) return bad("band.can_id_base", b.can_id_base, "must fit 29 bits");
  if (b.source == BandSource::candump && b.candump_path.empty()) {
    return "band.candump_path = \"\": a candump log is needed for band.source = \"candump\"";
  }
  if (!in(b.time_sync_interval_s, 0.05, 60.0)) {
    return bad("band.time_sync_interval_ms", b.time_sync_interval_s * 1e3, "must be 50..60000");
  }
  return validate(b.stiffness);
}

std::string validate_port(std::string_view key, int port, bool zero_ok) {
  if (port < (zero_ok ? 0 : 1) || port > 65535)
    return bad(key, port, zero_ok ? "must be 0..65535" : "must be 1..65535");
  return {};
}

}  // namespace

std::vector<ScheduledGift> default_demo_gifts(double seconds) {
  // Cubes on the right hand at a quarter, half and three quarters of the run
  // (the swell pattern's rising, peak and falling stiffness), a ball at the
  // chest in between; for runs too short for all four, only those that fit.
  std::vector<ScheduledGift> g{{0.2 * seconds, "cube", "RightHand"},
                               {0.35 * seconds, "ball", "Chest"},
                               {0.5 * seconds, "cube", "RightHand"},
                               {0.8 * seconds, "cube", "LeftHand"}};
  return g;
}

std::string validate(const DaemonConfig& c) {
  if (std::string e = validate_band(c.band); !e.empty()) return e;
  const TrackerConfig& t = c.tracker;
  if (std::string e = validate_port("tracker.listen_port", t.listen_port, true); !e.empty()) return e;
  if (t.listen_address.empty()) return "tracker.listen_address = \"\": an address is needed";
  // A clip is corrected offline or online; a live VMC performer's stream only
  // online (there is no whole clip); the tracker IK's legs are its own.
  const bool live_performer = t.source == TrackerSource::vmc && t.vmc_mode == VmcMode::performer;
  if (t.balance == balance::BalanceMode::online && t.source != TrackerSource::bvh && !live_performer) {
    return fmt::format(
        "tracker.balance = \"online\": the balance filter runs on a bvh source or a VMC performer stream "
        "(tracker.source = \"{}\", tracker.vmc_mode = \"{}\")",
        to_string(t.source), to_string(t.vmc_mode));
  }
  if (t.balance == balance::BalanceMode::offline && t.source != TrackerSource::bvh) {
    return fmt::format(
        "tracker.balance = \"offline\": the offline filter needs a whole clip (tracker.source = \"bvh\"); a live "
        "VMC performer stream takes \"online\" (tracker.source = \"{}\")",
        to_string(t.source));
  }
  if (!in(t.balance_lookahead_s, 0.001, balance::kMaxLookahead_s)) {
    return bad("tracker.balance_lookahead_ms", t.balance_lookahead_s * 1e3, "must be 1..250");
  }
  if (std::string e = validate(t.buffer); !e.empty()) return e;
  const PhysicsConfig& p = c.physics;
  if (!in(p.rate_hz, 100.0, 4000.0)) return bad("physics.rate_hz", p.rate_hz, "must be 100..4000");
  if (p.max_catch_up_ticks < 1 || p.max_catch_up_ticks > 100) {
    return bad("physics.max_catch_up_ticks", p.max_catch_up_ticks, "must be 1..100");
  }
  if (p.realtime_priority < 0 || p.realtime_priority > 99) {
    return bad("physics.realtime_priority", p.realtime_priority, "must be 0..99");
  }
  if (!in(p.stiffness_rate_per_s, 0.1, 1000.0)) {
    return bad("physics.stiffness_rate_per_s", p.stiffness_rate_per_s, "must be 0.1..1000");
  }
  const OutputConfig& o = c.output;
  if (o.host.empty()) return "output.host = \"\": an address is needed";
  if (std::string e = validate_port("output.port", o.port, false); !e.empty()) return e;
  if (!in(o.rate_hz, 1.0, 200.0)) {
    return bad("output.rate_hz", o.rate_hz, "must be 1..200 (faster crashes some receivers)");
  }
  if (std::string e = validate_port("control.port", c.control.port, true); !e.empty()) return e;
  if (c.control.address.empty()) return "control.address = \"\": an address is needed";
  if (std::string e = validate_port("viewer.port", c.viewer.port, true); !e.empty()) return e;
  if (c.viewer.address.empty()) return "viewer.address = \"\": an address is needed";
  if (!in(c.viewer.rate_hz, 1.0, 120.0)) return bad("viewer.rate_hz", c.viewer.rate_hz, "must be 1..120");
  static constexpr std::array<std::string_view, 7> kLevels{"trace", "debug",    "info", "warn",
                                                           "error", "critical", "off"};
  if (std::find(kLevels.begin(), kLevels.end(), c.log.level) == kLevels.end()) {
    return fmt::format("log.level = \"{}\": must be trace, debug, info, warn, error, critical or off", c.log.level);
  }
  if (!in(c.log.status_interval_s, 0.0, 3600.0)) {
    return bad("log.status_interval_s", c.log.status_interval_s, "must be 0..3600 (0: no status line)");
  }
  if (!in(c.demo.seconds, 0.1, 1e6)) return bad("demo.seconds", c.demo.seconds, "must be 0.1..1000000");
  for (std::size_t i = 0; i < c.demo.gifts.size(); ++i) {
    const ScheduledGift& g = c.demo.gifts[i];
    if (!in(g.at_s, 0.0, 1e6)) return bad(fmt::format("demo.gifts[{}].at_s", i), g.at_s, "must be 0..1000000");
    if (g.kind != "ball" && g.kind != "cube") {
      return fmt::format("demo.gifts[{}].kind = \"{}\": must be ball or cube", i, g.kind);
    }
    if (!sim::bone_from_name(g.bone)) {
      return fmt::format("demo.gifts[{}].bone = \"{}\": not a humanoid bone (HumanBodyBones name)", i, g.bone);
    }
  }
  return {};
}

std::string check_files(const DaemonConfig& c) {
  if (c.viewer.enabled && !c.viewer.vrm.empty()) {
    if (const viewer::VrmFileInfo info = viewer::check_vrm_file(c.viewer.vrm); !info.error.empty()) {
      return fmt::format("viewer.vrm = \"{}\": {}", c.viewer.vrm, info.error);
    }
  }
  return {};
}

std::string_view to_string(BandSource s) {
  switch (s) {
    case BandSource::sim: return "sim";
    case BandSource::socket: return "socket";
    case BandSource::hid: return "hid";
    case BandSource::can: return "can";
    case BandSource::candump: return "candump";
    case BandSource::none: return "none";
  }
  return "?";
}
std::string_view to_string(SimLink s) { return s == SimLink::hid ? "hid" : "can"; }
std::string_view to_string(TrackerSource s) {
  switch (s) {
    case TrackerSource::bvh: return "bvh";
    case TrackerSource::vmc: return "vmc";
    case TrackerSource::none: return "none";
  }
  return "?";
}
std::string_view to_string(VmcMode s) { return s == VmcMode::performer ? "performer" : "trackers"; }
std::string_view to_string(FeedforwardChoice s) {
  switch (s) {
    case FeedforwardChoice::simulation: return "simulation";
    case FeedforwardChoice::inverse_dynamics: return "inverse_dynamics";
    case FeedforwardChoice::none: return "none";
  }
  return "?";
}

}  // namespace tonus::daemon
