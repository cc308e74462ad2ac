// tonusd's configuration: every setting with its default (what runs with no
// config file), grouped as the TOML file's tables. config_file.hpp reads and
// writes the file; validate() checks every key and names the first bad one.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tonus/host/balance/stage.hpp"
#include "tonus/host/daemon/pose_buffer.hpp"
#include "tonus/host/daemon/stiffness_input.hpp"

namespace tonus::daemon {

enum class BandSource : std::uint8_t { sim, socket, hid, can, candump, none };
enum class SimLink : std::uint8_t { hid, can };
enum class TrackerSource : std::uint8_t { bvh, vmc, none };
enum class VmcMode : std::uint8_t { performer, trackers };
enum class FeedforwardChoice : std::uint8_t { simulation, inverse_dynamics, none };

struct BandConfig {
  BandSource source = BandSource::sim;
  // sim: tonus-band-sim spawned over a socketpair.
  std::string sim_path;                 // empty: tonus-band-sim beside tonusd
  std::string sim_synthetic = "swell";  // a tonus-band-sim --synthetic scenario ...
  std::string sim_recording;            // ... or an EMG recording (takes precedence)
  double sim_seconds = 0.0;             // the simulator's run; 0: as long as tonusd runs
  std::uint64_t sim_seed = 1;
  std::vector<std::string> sim_args;  // appended to the simulator's command line (e.g. "--swell-period", "20")
  SimLink sim_link = SimLink::hid;    // sim and socket: which of the simulator's links
  // socket: a tonus-band-sim already serving --hid-socket / --can-socket PATH.
  std::string sim_socket;
  // hid: a real band over hidapi.
  std::uint16_t vid = 0x1209;
  std::uint16_t pid = 0x0001;  // pid.codes test PID (firmware/usb descriptors.hpp)
  std::string serial;          // empty: the first band found
  // can: SocketCAN.
  std::string can_interface = "can0";
  int can_node = 1;
  std::uint32_t can_id_base = 0;
  // candump: a log replayed at its own pace.
  std::string candump_path;
  bool candump_loop = false;
  // Staleness and time.
  StiffnessInputConfig stiffness;
  double time_sync_interval_s = 0.5;
};

struct TrackerConfig {
  TrackerSource source = TrackerSource::bvh;
  std::string bvh_path;  // empty: the bundled clip (tests/data/cmu_02_walk.bvh)
  bool bvh_loop = true;
  // bvh: the balance filter on the clip before it plays (docs/balance.md):
  // off, offline (the whole clip at load) or online (the streaming filter,
  // balance_lookahead_s ahead; run over the clip at load, which gives what a
  // live stream through it would).
  balance::BalanceMode balance = balance::BalanceMode::off;
  double balance_lookahead_s = balance::kMaxLookahead_s;
  VmcMode vmc_mode = VmcMode::performer;
  std::string listen_address = "127.0.0.1";
  int listen_port = 39540;
  PoseBufferConfig buffer;
};

struct PhysicsConfig {
  double rate_hz = 1000.0;
  int max_catch_up_ticks = 4;  // a late wake-up runs at most this many ticks at once, then skips ahead
  int realtime_priority = 20;  // SCHED_FIFO priority when permitted; 0: never try
  bool lock_memory = true;     // mlockall when permitted
  FeedforwardChoice feedforward = FeedforwardChoice::simulation;
  double stiffness_rate_per_s = 10.0;  // the controller's rate limit (0 -> 1 in 0.1 s)
};

struct OutputConfig {
  bool enabled = true;
  std::string host = "127.0.0.1";
  int port = 39539;
  double rate_hz = 60.0;  // at most 200 (faster crashes some receivers)
  bool bundle = true;
};

struct ControlConfig {
  bool enabled = true;
  std::string address = "127.0.0.1";
  int port = 39545;
  bool allow_remote = false;  // must be true for any address beyond loopback
};

// The live web viewer (host/viewer, docs/viewer.md): the page and its
// WebSocket on one port.
struct ViewerConfig {
  bool enabled = true;
  std::string address = "127.0.0.1";
  int port = 39546;
  bool allow_remote = false;  // must be true for any address beyond loopback
  double rate_hz = 50.0;      // frames a second to the page (30..60 is plenty)
  std::string web_root;       // empty: the page in the source tree (host/viewer/web)
  std::string vrm;            // a .vrm avatar the page draws beside the capsules; empty: none
};

struct LogConfig {
  std::string level = "info";  // trace, debug, info, warn, error, off
  double status_interval_s = 5.0;
};

// A gift on the demo's schedule.
struct ScheduledGift {
  double at_s = 0.0;
  std::string kind = "cube";  // ball | cube
  std::string bone = "RightHand";
};

struct DemoConfig {
  double seconds = 20.0;
  std::vector<ScheduledGift> gifts;  // empty: the built-in schedule
};

struct DaemonConfig {
  BandConfig band;
  TrackerConfig tracker;
  PhysicsConfig physics;
  OutputConfig output;
  ControlConfig control;
  ViewerConfig viewer;
  LogConfig log;
  DemoConfig demo;
};

// The built-in demo schedule: a ball at the chest and cubes on the right hand,
// spread over `seconds` so they meet low and high stiffness.
std::vector<ScheduledGift> default_demo_gifts(double seconds);

// Empty when usable, else "key = value: what is wrong" for the first bad key.
// Values only: no file is opened (a recording's config validates anywhere).
std::string validate(const DaemonConfig& c);

// The files the run needs before anything starts: viewer.vrm (when the viewer
// is on) must be a glTF binary under the size cap (viewer/vrm_file.hpp).
// Empty, or "key = value: what is wrong".
std::string check_files(const DaemonConfig& c);

std::string_view to_string(BandSource s);
std::string_view to_string(SimLink s);
std::string_view to_string(TrackerSource s);
std::string_view to_string(VmcMode s);
std::string_view to_string(FeedforwardChoice s);

}  // namespace tonus::daemon
