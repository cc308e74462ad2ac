// Typed payloads of command requests and responses, and their codecs.
//
// Every payload has a fixed wire size; a payload longer than that is accepted
// and the tail ignored (a newer minor version may append fields), a shorter
// one is Error::bad_length. Byte tables are in docs/protocol.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "tonus/protocol/command.hpp"
#include "tonus/protocol/error.hpp"
#include "tonus/protocol/limits.hpp"
#include "tonus/protocol/wire.hpp"

namespace tonus::proto {

inline constexpr std::uint8_t kPairUnused = 0xFF;  // pair_group entry of a pair feeding no group

// Why the device last started (DeviceInfo.reset_cause).
enum class ResetCause : std::uint8_t {
  unknown = 0,
  power_on = 1,  // power-on or brown-out reset
  pin = 2,       // the reset pin (a debugger, a button)
  software = 3,  // the `reset` command, or a firmware update
  watchdog = 4,  // the independent or window watchdog
  low_power = 5,
};

namespace feature_bit {
inline constexpr std::uint32_t boot_epoch = 1U << 0U;  // the stream's byte 3 is a boot epoch
inline constexpr std::uint32_t fault_log = 1U << 1U;   // get_log
inline constexpr std::uint32_t bootloader = 1U << 2U;  // enter_bootloader reboots into an update bootloader
}  // namespace feature_bit

// get_device_info response. Minor 1 appended protocol_minor..reset_cause; a
// 29-byte answer (minor 0) reads with those fields zero.
struct DeviceInfo {
  static constexpr std::size_t kMinWireSize = 29;
  static constexpr std::size_t kWireSize = 43;
  std::uint8_t firmware_major = 0;
  std::uint8_t firmware_minor = 0;
  std::uint8_t firmware_patch = 0;
  std::uint8_t protocol_version = kProtocolVersion;
  std::uint64_t serial = 0;
  std::uint8_t hardware_revision = 0;
  std::uint8_t channel_count = 8;
  std::uint8_t group_count = 4;
  std::uint8_t pair_count = 4;
  std::uint16_t sample_rate_hz = 2000;
  std::uint16_t report_rate_hz = 500;
  std::array<std::uint8_t, kMaxPairs> pair_group{};  // group of each pair, or kPairUnused
  std::uint8_t transports = 0;                       // transport_bit::*
  // minor 1
  std::uint8_t protocol_minor = 0;
  std::uint32_t features = 0;    // feature_bit::*
  std::uint32_t build_id = 0;    // the firmware's source revision (git commit, first 8 hex digits), 0 unknown
  std::uint32_t boot_count = 0;  // boots since the storage was last erased, 0 unknown
  ResetCause reset_cause = ResetCause::unknown;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const DeviceInfo&, const DeviceInfo&) = default;
};

namespace transport_bit {
inline constexpr std::uint8_t usb_hid = 1U << 0U;
inline constexpr std::uint8_t can = 1U << 1U;
}  // namespace transport_bit

// time_sync: NTP-style exchange. The host stamps t1 on send and t4 on receipt;
// the device stamps t2 on receipt and t3 on send, on its 64-bit microsecond clock.
struct TimeSyncRequest {
  static constexpr std::size_t kWireSize = 8;
  std::uint64_t host_time_us = 0;  // t1, echoed back

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const TimeSyncRequest&, const TimeSyncRequest&) = default;
};

struct TimeSyncResponse {
  static constexpr std::size_t kWireSize = 24;
  std::uint64_t host_time_us = 0;  // t1 echoed
  std::uint64_t device_rx_us = 0;  // t2
  std::uint64_t device_tx_us = 0;  // t3

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const TimeSyncResponse&, const TimeSyncResponse&) = default;
};

// get_stats response: counters since power-on.
struct DeviceStats {
  static constexpr std::size_t kWireSize = 24;
  std::uint32_t uptime_ms = 0;
  std::uint32_t reports_sent = 0;
  std::uint32_t lost_blocks = 0;  // sample blocks overwritten before processing
  std::uint32_t late_blocks = 0;  // blocks processed after their deadline
  std::uint32_t tx_dropped = 0;   // reports dropped because the link was busy
  std::uint16_t commands_rejected = 0;
  std::uint16_t watchdog_resets = 0;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const DeviceStats&, const DeviceStats&) = default;
};

enum class CalibrationPhase : std::uint8_t {
  rest = 1,             // baseline per channel, performer relaxed
  max_contraction = 2,  // maximal voluntary contraction per selected channel
  co_contraction = 3,   // optional co-contraction reference per pair
};

// calibration_start request.
struct CalibrationStart {
  static constexpr std::size_t kWireSize = 5;
  static constexpr std::uint16_t kMinDurationMs = 100;
  static constexpr std::uint16_t kMaxDurationMs = 60000;
  CalibrationPhase phase = CalibrationPhase::rest;
  std::uint16_t channel_mask = 0xFFFF;  // channels taking part (bits above channel_count ignored)
  std::uint16_t duration_ms = 3000;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const CalibrationStart&, const CalibrationStart&) = default;
};

enum class CalibrationState : std::uint8_t {
  idle = 0,
  running = 1,
  done = 2,
  aborted = 3,
  timed_out = 4,
  failed = 5,
};

// calibration_status response.
struct CalibrationStatus {
  static constexpr std::size_t kWireSize = 6;
  CalibrationState state = CalibrationState::idle;
  std::uint8_t phase = 0;             // CalibrationPhase of the current/last phase, 0 = none
  std::uint8_t progress_pct = 0;      // 0..100
  std::uint16_t calibrated_mask = 0;  // channels holding a valid baseline and gain
  std::uint8_t phases_done = 0;       // bit (phase-1) set when that phase completed

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const CalibrationStatus&, const CalibrationStatus&) = default;
};

enum class EnvelopeMode : std::uint8_t { linear = 0, moving_rms = 1 };
enum class CoContractionMeasure : std::uint8_t { min_normalised = 0, cci = 1 };
enum class LevelCurve : std::uint8_t { linear = 0, power = 1 };

// get_config response and set_config request. Frequencies in decihertz (0.1 Hz)
// so that corners like 20.0 Hz and 450.0 Hz are exact integers on the wire.
struct DeviceConfig {
  static constexpr std::size_t kMinWireSize = 31;  // minor 0
  static constexpr std::size_t kWireSize = 35;
  std::uint16_t sample_rate_hz = 2000;
  // 500 Hz leaves every other 1 ms USB frame free for command responses.
  std::uint16_t report_rate_hz = 500;
  std::uint16_t highpass_dhz = 200;  // 20.0 Hz (SENIAM); 0 = off
  std::uint16_t lowpass_dhz = 4500;  // 450.0 Hz; 0 = off
  std::uint8_t notch_hz = 50;        // 0 = off, 50 or 60
  std::uint8_t notch_harmonics = 4;  // fundamental + harmonics below Nyquist, 1..8
  EnvelopeMode envelope_mode = EnvelopeMode::linear;
  std::uint16_t envelope_tau_ms = 100;
  std::array<std::uint8_t, kMaxPairs> pair_group{0, 1, 2, 3, kPairUnused, kPairUnused, kPairUnused, kPairUnused};
  CoContractionMeasure measure = CoContractionMeasure::min_normalised;
  std::uint16_t dead_band = 1311;  // level units (~2 % of full scale)
  std::uint16_t hysteresis = 655;  // level units (~1 %)
  LevelCurve curve = LevelCurve::linear;
  std::uint16_t curve_exponent_milli = 1000;
  std::uint8_t can_node_id = 1;            // 0..31
  std::uint8_t can_envelope_divider = 10;  // envelopes on CAN every Nth report; 0 = never
  // minor 1: where the CAN id plan sits (can.hpp): 0 = the 11-bit ids, else a
  // 29-bit base (a multiple of 0x800) for a bus shared with CANopen.
  std::uint32_t can_id_base = 0;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const DeviceConfig&, const DeviceConfig&) = default;
};

// Fields of DeviceConfig in wire order; check_config names the first bad one.
enum class ConfigField : std::uint8_t {
  none = 0xFF,
  sample_rate_hz = 0,
  report_rate_hz,
  highpass_dhz,
  lowpass_dhz,
  notch_hz,
  notch_harmonics,
  envelope_mode,
  envelope_tau_ms,
  pair_group,
  measure,
  dead_band,
  hysteresis,
  curve,
  curve_exponent_milli,
  can_node_id,
  can_envelope_divider,
  can_id_base,
};

const char* to_string(ConfigField f);

// Range rules shared by host (before sending) and firmware (before applying).
// group_count is the device's number of stiffness groups.
ConfigField check_config(const DeviceConfig& cfg, std::uint8_t group_count);

// set_config response: which field was refused (Status::bad_value), or none.
struct SetConfigResult {
  static constexpr std::size_t kWireSize = 1;
  ConfigField rejected = ConfigField::none;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const SetConfigResult&, const SetConfigResult&) = default;
};

enum class ResetKind : std::uint8_t { reboot = 0, factory_defaults = 1 };

// reset request. The device answers, then resets.
struct ResetRequest {
  static constexpr std::size_t kWireSize = 1;
  ResetKind kind = ResetKind::reboot;

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const ResetRequest&, const ResetRequest&) = default;
};

// What a fault-log entry records.
enum class FaultCode : std::uint8_t {
  none = 0,               // an unused entry
  sampler_restarted = 1,  // no sample block for 200 ms: the sampler was restarted (arg: restarts)
  sampler_stalled = 2,    // still none after the restart: fault state, the watchdog will reset
  storage_corrupt = 3,    // no valid record at boot: defaults in use (arg: LoadResult)
  storage_error = 4,      // a save or its verification failed
  watchdog_reset = 5,     // this boot followed a watchdog reset
  blocks_lost = 6,        // sample blocks overwritten before processing (arg: count, saturating)
  can_down = 7,           // the CAN port refused frames: no bus, or bus-off (arg: frames)
  config_rejected = 8,    // a stored or requested configuration failed the device's check (arg: field)
};

// One fault-log entry: device time in ms of its first occurrence (wraps after
// 49.7 days), code, how many more times it recurred right after (merged,
// saturating), and an argument.
struct LogEntry {
  std::uint32_t time_ms = 0;
  FaultCode code = FaultCode::none;
  std::uint8_t repeats = 0;
  std::uint16_t arg = 0;
  friend bool operator==(const LogEntry&, const LogEntry&) = default;
};

// get_log response: the oldest entries not read yet (at most 6), which the
// response then removes from the device's log; `dropped` counts entries lost
// to a full log since the last read, `more` that entries remain.
struct FaultLog {
  static constexpr std::size_t kMaxEntries = 6;
  static constexpr std::size_t kEntrySize = 8;  // u32 time_ms, u8 code, u8 repeats, u16 arg
  static constexpr std::size_t kWireSize = 4 + kMaxEntries * kEntrySize;
  std::uint8_t count = 0;
  std::uint8_t more = 0;  // 1 if the device holds further entries
  std::uint16_t dropped = 0;
  std::array<LogEntry, kMaxEntries> entries{};

  void write(ByteWriter& w) const;
  Error read(ByteReader& r);
  friend bool operator==(const FaultLog&, const FaultLog&) = default;
};

// Builds a request or response carrying a typed payload.
template <class Payload>
Error make_request(Opcode op, std::uint8_t token, const Payload& p, Request& out) {
  out = Request{};
  out.opcode = op;
  out.token = token;
  ByteWriter w(out.payload);
  p.write(w);
  if (!w.ok()) return w.error();
  out.length = static_cast<std::uint8_t>(w.size());
  return Error::ok;
}

inline Request make_request(Opcode op, std::uint8_t token) {
  Request r{};
  r.opcode = op;
  r.token = token;
  return r;
}

template <class Payload>
Error make_response(const Request& req, Status status, const Payload& p, Response& out) {
  out = Response{};
  out.opcode = req.opcode;
  out.token = req.token;
  out.status = status;
  ByteWriter w(out.payload);
  p.write(w);
  if (!w.ok()) return w.error();
  out.length = static_cast<std::uint8_t>(w.size());
  return Error::ok;
}

inline Response make_response(const Request& req, Status status) {
  Response r{};
  r.opcode = req.opcode;
  r.token = req.token;
  r.status = status;
  return r;
}

// The shortest payload a decoder accepts: the minor-0 size where a later
// minor appended fields.
template <class Payload>
constexpr std::size_t min_wire_size() {
  if constexpr (requires { Payload::kMinWireSize; }) {
    return Payload::kMinWireSize;
  } else {
    return Payload::kWireSize;
  }
}

// Reads the typed payload of a request or response.
template <class Payload, class Message>
Error read_payload(const Message& msg, Payload& out) {
  if (msg.length < min_wire_size<Payload>()) return Error::bad_length;
  ByteReader r(msg.body());
  Payload p{};
  if (Error e = p.read(r); e != Error::ok) return e;
  out = p;
  return Error::ok;
}

}  // namespace tonus::proto
