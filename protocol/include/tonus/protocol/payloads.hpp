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

// get_device_info response.
struct DeviceInfo {
  static constexpr std::size_t kWireSize = 29;
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
  std::uint16_t report_rate_hz = 1000;
  std::array<std::uint8_t, kMaxPairs> pair_group{};  // group of each pair, or kPairUnused
  std::uint8_t transports = 0;                       // transport_bit::*

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
  static constexpr std::size_t kWireSize = 31;
  std::uint16_t sample_rate_hz = 2000;
  std::uint16_t report_rate_hz = 1000;
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

// Reads the typed payload of a request or response.
template <class Payload, class Message>
Error read_payload(const Message& msg, Payload& out) {
  if (msg.length < Payload::kWireSize) return Error::bad_length;
  ByteReader r(msg.body());
  Payload p{};
  if (Error e = p.read(r); e != Error::ok) return e;
  out = p;
  return Error::ok;
}

}  // namespace tonus::proto
