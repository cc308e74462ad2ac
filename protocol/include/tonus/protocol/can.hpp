// CAN binding: classic CAN 2.0A (11-bit ids, <= 8 data bytes).
//
// ID plan: id = function base | node id (0..31). Lower ids win arbitration,
// so the stream outranks commands, which outrank the heartbeat.
//   0x100 STATUS     seq u16, device_time_us u32, status u16       (opens a cycle)
//   0x120 LEVELS0    levels of groups 0..3, u16 each
//   0x140 LEVELS1    levels of groups 4..5
//   0x160..0x1C0 ENV0..ENV3  envelopes of channels 4k..4k+3 (every Nth cycle)
//   0x1E0 FLAGS      electrode_off u16, saturation u16, artifact u16,
//                    counts u8 (group_count-1 << 4 | channel_count-1),
//                    sequence low byte u8                          (closes a cycle)
//   0x580 RESPONSE   segmented response message (device -> host)
//   0x600 REQUEST    segmented request message (host -> device)
//   0x700 HEARTBEAT  state u8, protocol version u8, status u16, uptime_ms u32
// A stream cycle is sent in that order; the host assembles it in StreamAssembler.
// The sequence low byte in FLAGS ties it to its STATUS, so that frames of two
// cycles never merge into one message when closing or opening frames are lost.
// Command messages (<= 63 bytes) are split in segments of 7 bytes after a
// header byte: high nibble = segment count (1..9), low nibble = index.
// protocol/tonus.dbc describes every frame for node 1.
//
// ID base (DeviceConfig.can_id_base, minor 1). These 11-bit ids reuse the
// CANopen bases (0x580/0x600/0x700 are SDO and NMT error control), so a band
// alone on its bus uses them (base 0) but a bus shared with CANopen devices
// must not. A nonzero base moves the whole plan to 29-bit (extended) ids
// base + plan id: CANopen's predefined connection set uses only 11-bit ids,
// so the two never collide. The base is a multiple of 0x800 up to 0x1FFFF800.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/error.hpp"
#include "tonus/protocol/limits.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::proto {

// Transport-neutral classic CAN frame (the host maps it to SocketCAN's struct can_frame).
struct CanFrame {
  static constexpr std::uint8_t kExtended = 1U << 0U;  // 29-bit id
  static constexpr std::uint8_t kRemote = 1U << 1U;    // RTR frame
  static constexpr std::uint8_t kErrorFrame = 1U << 2U;
  std::uint32_t id = 0;
  std::uint8_t dlc = 0;  // 0..8
  std::uint8_t flags = 0;
  std::array<std::uint8_t, 8> data{};

  // Clamped to the 8 data bytes, so a frame with an invalid dlc can never be read past its end.
  [[nodiscard]] std::span<const std::uint8_t> payload() const {
    return {data.data(), dlc <= data.size() ? dlc : data.size()};
  }
  friend bool operator==(const CanFrame&, const CanFrame&) = default;
};

namespace can {

inline constexpr std::uint8_t kMaxNodeId = 31;

// The CAN binding's own bit in the STATUS frame's status word: this cycle
// carries envelope frames. Without it a cycle whose envelope frames were all
// lost would look like one sent without them. Device status bits never use
// it (stream.hpp); the assembler strips it, and a decoder that ignores it
// (an older host) reads the cycle as before.
inline constexpr std::uint16_t kStatusEnvelopesFollow = 0x8000;
inline constexpr std::uint32_t kNodeMask = 0x1F;

enum class Function : std::uint16_t {
  status = 0x100,
  levels0 = 0x120,
  levels1 = 0x140,
  envelope0 = 0x160,
  envelope1 = 0x180,
  envelope2 = 0x1A0,
  envelope3 = 0x1C0,
  flags = 0x1E0,
  response = 0x580,
  request = 0x600,
  heartbeat = 0x700,
};

inline constexpr std::uint32_t kIdBaseStep = 0x800;
inline constexpr std::uint32_t kMaxIdBase = 0x1FFFF800;
constexpr bool valid_id_base(std::uint32_t base) { return base % kIdBaseStep == 0 && base <= kMaxIdBase; }

// The plan's id of a function and node at `id_base` (extended when nonzero).
constexpr std::uint32_t make_id(Function f, std::uint8_t node, std::uint32_t id_base = 0) {
  return id_base + (static_cast<std::uint32_t>(f) | (node & kNodeMask));
}

// Splits a standard id into function and node; false for ids outside the plan.
bool split_id(std::uint32_t id, Function& f, std::uint8_t& node);
// Splits a frame's id at `id_base`: false unless it is a data frame of the plan
// (standard for base 0, extended with that base otherwise).
bool split_frame(const CanFrame& frame, std::uint32_t id_base, Function& f, std::uint8_t& node);

inline constexpr std::size_t kGroupsPerFrame = 4;
inline constexpr std::size_t kChannelsPerFrame = 4;
inline constexpr std::size_t kMaxStreamFrames = 8;  // status + 2 levels + 4 envelope + flags

// Frames of one stream cycle, in send order. Envelope frames are included only
// when `with_envelopes` (the device sends them every can_envelope_divider cycles).
Error encode_stream(const StreamMessage& msg, std::uint8_t node, bool with_envelopes, std::span<CanFrame> out,
                    std::size_t& count, std::uint32_t id_base = 0);

// Reassembles stream cycles of one node. Frames of other nodes are ignored.
// A cycle is delivered when its FLAGS frame arrives and every levels frame the
// counts call for was seen; envelopes missing from a cycle keep their previous
// values (envelopes_fresh() says whether this cycle carried them).
class StreamAssembler {
 public:
  explicit StreamAssembler(std::uint8_t node, std::uint32_t id_base = 0) : node_(node), id_base_(id_base) {}

  // Returns Error::ok and sets `complete` when `message()` holds a new cycle.
  // Malformed frames return an error and void the cycle in progress.
  Error push(const CanFrame& frame, bool& complete);

  [[nodiscard]] const StreamMessage& message() const { return msg_; }
  [[nodiscard]] bool envelopes_fresh() const { return envelopes_fresh_; }
  [[nodiscard]] std::uint32_t incomplete_cycles() const { return incomplete_cycles_; }
  [[nodiscard]] std::uint32_t stray_frames() const { return stray_frames_; }

 private:
  void abandon_cycle();

  std::uint8_t node_;
  std::uint32_t id_base_;
  bool in_cycle_ = false;
  std::uint8_t seen_ = 0;  // bit per stream function index (levels0.. envelope3)
  std::array<std::uint8_t, 6> dlc_{};
  StreamMessage pending_{};
  StreamMessage msg_{};
  bool envelopes_fresh_ = false;
  bool envelopes_expected_ = false;  // the STATUS frame said envelope frames follow
  std::uint32_t incomplete_cycles_ = 0;
  std::uint32_t stray_frames_ = 0;
};

enum class NodeState : std::uint8_t { booting = 0, running = 1, calibrating = 2, fault = 3 };

struct Heartbeat {
  NodeState state = NodeState::running;
  std::uint8_t protocol_version = kProtocolVersion;
  std::uint16_t status = 0;  // status_bit::*
  std::uint32_t uptime_ms = 0;
  friend bool operator==(const Heartbeat&, const Heartbeat&) = default;
};

CanFrame encode_heartbeat(const Heartbeat& hb, std::uint8_t node, std::uint32_t id_base = 0);
Error decode_heartbeat(const CanFrame& frame, Heartbeat& out, std::uint32_t id_base = 0);

// Segmentation of a command request/response message (bytes as produced by
// encode_request / encode_response) into REQUEST or RESPONSE frames.
inline constexpr std::size_t kSegmentData = 7;
inline constexpr std::size_t kMaxSegments = (kMaxMessageSize + kSegmentData - 1) / kSegmentData;  // 9

Error segment(std::span<const std::uint8_t> message, Function f, std::uint8_t node, std::span<CanFrame> out,
              std::size_t& count, std::uint32_t id_base = 0);

// Collects the segments of one function/node. A new index-0 segment restarts;
// a gap, duplicate or count change voids the message (Error::out_of_order).
// The message's own length and CRC are checked by the command decoder.
class Reassembler {
 public:
  Reassembler(Function f, std::uint8_t node, std::uint32_t id_base = 0)
      : function_(f), node_(node), id_base_(id_base) {}

  Error push(const CanFrame& frame, bool& complete);
  [[nodiscard]] std::span<const std::uint8_t> message() const { return {buffer_.data(), size_}; }
  void reset();

 private:
  Function function_;
  std::uint8_t node_;
  std::uint32_t id_base_;
  std::uint8_t total_ = 0;
  std::uint8_t expected_ = 0;
  std::size_t size_ = 0;
  std::array<std::uint8_t, kMaxSegments * kSegmentData> buffer_{};
};

}  // namespace can
}  // namespace tonus::proto
