// Sends the humanoid's pose to an avatar engine (the VMC "marionette":
// VSeeFace, Warudo, VirtualMotionCapture, Unity with EVMC4U) as OSC over UDP
// (liblo). One send() is one frame:
//   /VMC/Ext/OK (int 1 loaded, int 3 calibrated, int 0 mode, int 1 tracking ok)
//   /VMC/Ext/T (float time_s)
//   /VMC/Ext/Root/Pos ("root", px py pz qx qy qz qw)
//   /VMC/Ext/Bone/Pos (name, px py pz qx qy qz qw) for each of the 21 bones
//   /tonus/Object/Pos per object, or /tonus/Object/Clear when there is none
//   /tonus/Stiffness (right_arm, left_arm, trunk, legs) when given
// in OSC bundles of at most max_datagram_bytes each (the first holds OK and
// T), or as plain messages for receivers that cannot parse bundles.
// docs/vmc.md gives every field.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "tonus/host/vmc/pose_out.hpp"

namespace tonus::vmc {

struct SenderOptions {
  std::string host = "127.0.0.1";  // the avatar engine's address (name or numeric)
  int port = 39539;                // VMC's marionette default
  bool bundle = true;              // false: one datagram per message
  // Largest OSC bundle (serialised, without the UDP/IP headers). 1500 by
  // default; 1472 keeps a datagram within one Ethernet frame on a LAN.
  std::size_t max_datagram_bytes = 1500;
};

struct SenderCounters {
  std::uint64_t frames = 0;       // send() calls that sent everything
  std::uint64_t bundles = 0;      // bundles sent
  std::uint64_t messages = 0;     // OSC messages sent (in bundles or not)
  std::uint64_t bytes = 0;        // OSC payload bytes sent
  std::uint64_t send_errors = 0;  // datagrams the socket refused
  std::uint64_t rejected = 0;     // frames not sent: a non-finite value in the pose or an object
  // FNV-1a (64 bits) over every datagram's bytes, in order: two runs whose
  // hashes match sent the same bytes (tonusd's replay checks this).
  std::uint64_t wire_hash = 14695981039346656037ULL;
};

class VmcSender {
 public:
  static constexpr std::size_t kMinDatagramBytes = 256;    // every message fits, with room
  static constexpr std::size_t kMaxDatagramBytes = 65507;  // UDP over IPv4

  // Never throws: check ok() / error() (a bad port, size or address).
  explicit VmcSender(const SenderOptions& options = {});
  ~VmcSender();
  VmcSender(const VmcSender&) = delete;
  VmcSender& operator=(const VmcSender&) = delete;

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const SenderOptions& options() const { return options_; }

  // One frame. `time_s`: the sender's clock for /VMC/Ext/T (seconds since
  // start, say); `objects` in Unity frame (object_to_vmc); `stiffness` per
  // group (0..1, clamped; NaN left out), or nullptr to leave it out. True
  // when every datagram went out; false counts send_errors and sets
  // last_send_error(). A pose or object with a non-finite value is not sent
  // at all (never NaN on the wire): false, counted in `rejected`.
  bool send(const VmcPose& pose, double time_s, std::span<const VmcObject> objects,
            const std::array<float, 4>* stiffness);

  [[nodiscard]] const SenderCounters& counters() const { return counters_; }
  [[nodiscard]] const std::string& last_send_error() const { return last_send_error_; }

 private:
  SenderOptions options_;
  std::string error_;
  std::string last_send_error_;
  SenderCounters counters_;
  std::vector<unsigned char> scratch_;  // a datagram serialised for wire_hash
  void* address_ = nullptr;             // lo_address (liblo stays out of this header)
};

}  // namespace tonus::vmc
