// Receives VMC from a sender (a mocap app: VirtualMotionCapture, SlimeVR,
// XR Animator, a VSeeFace relay) on a UDP port, driven by the caller's
// thread: receive() decodes what has arrived and calls the handler once per
// frame. Two modes:
//   performer: /VMC/Ext/Root/Pos + /VMC/Ext/Bone/Pos -> reference::BodySample
//     (for reference::BodyRetarget), plus the sender's rest skeleton
//     (reference::SourceSkeleton) learnt from the bone positions.
//   tracker: /VMC/Ext/Hmd/Pos, /VMC/Ext/Con/Pos, /VMC/Ext/Tra/Pos ->
//     reference::TrackerFrame (for the tracker IK), serials mapped to
//     trackers by config or a heuristic (docs/vmc.md).
// Everything handed out is in the internal frame (unity_frame.hpp).
//
// A frame ends at the end of each top-level OSC bundle, or after each message
// that is not in a bundle; the handler is called for frames that carried a
// pose. Unknown addresses are counted as ignored, bad messages as malformed;
// nothing a sender can send makes it crash or throw. The socket is the
// receiver's own (bound to a chosen address: liblo 0.31's server binds the
// wildcard only); liblo decodes the messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/host/reference/trackers.hpp"

namespace tonus::vmc {

enum class ReceiverMode : std::uint8_t { performer, tracker };

struct ReceiverOptions {
  std::string address = "127.0.0.1";  // numeric IPv4 or IPv6; "0.0.0.0" for every interface
  int port = 39540;                   // VMC's performer-side default; 0: any free port (tests)
  ReceiverMode mode = ReceiverMode::performer;
  // Tracker mode: serial -> tracker, before any heuristic.
  std::vector<std::pair<std::string, reference::Tracker>> serial_map;
  // A quaternion whose norm is further than this from 1 is malformed.
  double unit_tolerance = 0.01;
  // Performer mode: frames with every required bone seen before the
  // skeleton is taken (bundles split a sender's frame: let all of it arrive).
  int skeleton_frames = 3;
};

struct ReceiverCounters {
  std::uint64_t datagrams = 0;
  std::uint64_t bundles = 0;   // top-level and nested
  std::uint64_t messages = 0;  // decoded OSC messages
  std::uint64_t frames = 0;    // handler calls (frames with a pose)
  std::uint64_t ignored = 0;   // addresses this mode does not use
  std::uint64_t malformed = 0;
  std::uint64_t unassigned = 0;          // tracker messages whose serial has no role (yet)
  std::uint64_t handler_exceptions = 0;  // thrown by the handler, caught
};

// What the sender last said about itself.
struct SenderStatus {
  bool ok_seen = false;  // a /VMC/Ext/OK arrived
  int loaded = 0;        // /VMC/Ext/OK's arguments (absent ones -1)
  int calibration_state = -1;
  int calibration_mode = -1;
  int tracking_status = -1;
  std::optional<double> time_s;       // the last /VMC/Ext/T
  std::int64_t last_arrival_us = -1;  // the last datagram, host steady clock
};

struct ReceivedFrame {
  ReceiverMode mode = ReceiverMode::performer;
  reference::BodySample body;           // performer mode: bones and root received in this frame
  reference::TrackerFrame trackers;     // tracker mode: trackers received in this frame (time_s = arrival)
  std::int64_t arrival_us = 0;          // host steady clock, when the frame's last datagram arrived
  std::optional<double> sender_time_s;  // the latest /VMC/Ext/T
  bool skeleton_ready = false;          // performer mode: VmcReceiver::skeleton() is set
};

class VmcReceiver {
 public:
  using Handler = std::function<void(const ReceivedFrame&)>;

  // Opens and binds the socket. Never throws: check ok() / error() (a port in
  // use, a bad address).
  explicit VmcReceiver(const ReceiverOptions& options = {});
  ~VmcReceiver();
  VmcReceiver(const VmcReceiver&) = delete;
  VmcReceiver& operator=(const VmcReceiver&) = delete;

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] int port() const { return port_; }  // the bound port (the chosen one when options.port = 0)
  [[nodiscard]] const ReceiverOptions& options() const { return options_; }

  void set_handler(Handler handler) { handler_ = std::move(handler); }

  // Waits up to timeout_ms (0 or less: not at all) for a datagram, then
  // decodes every datagram waiting (at most kMaxDatagramsPerCall). Returns
  // how many datagrams it decoded. Never throws.
  int receive(int timeout_ms);
  static constexpr int kMaxDatagramsPerCall = 4096;

  // Decodes one datagram as if it had arrived at arrival_us (host steady
  // clock), through the same path as receive(): for replaying captures and
  // for the fuzzer. Works without a socket. Never throws.
  void decode(const unsigned char* datagram, std::size_t size, std::int64_t arrival_us);

  [[nodiscard]] const ReceiverCounters& counters() const;
  [[nodiscard]] const SenderStatus& sender() const;

  // Performer mode: the sender's rest skeleton (its bone offsets, identity
  // rest rotations: a VRM in VMC is a normalised T-pose), set once every
  // required bone (reference::BodyRetarget::create's list) has been in
  // skeleton_frames frames. Empty until then.
  [[nodiscard]] const std::optional<reference::SourceSkeleton>& skeleton() const;
  void reset_skeleton();  // learn again (the sender changed avatar)

  // Tracker mode: the serials the heuristic assigned so far (the explicit
  // map's entries are not repeated).
  [[nodiscard]] const std::vector<std::pair<std::string, reference::Tracker>>& tracker_assignments() const;

 private:
  struct State;  // the decoder (receiver.cpp)

  ReceiverOptions options_;
  std::string error_;
  int fd_ = -1;
  int port_ = 0;
  Handler handler_;
  std::unique_ptr<State> state_;
};

}  // namespace tonus::vmc
