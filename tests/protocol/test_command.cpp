#include <doctest/doctest.h>

#include <algorithm>
#include <array>

#include "support/mutate.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus::proto;

namespace {

template <class Payload>
void check_request_round_trip(Opcode op, const Payload& p) {
  Request req{};
  REQUIRE(make_request(op, 0x5A, p, req) == Error::ok);
  CHECK(req.length == Payload::kWireSize);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_request(req, buf, n) == Error::ok);
  CHECK(n == kRequestOverhead + Payload::kWireSize);
  Request back{};
  REQUIRE(decode_request(std::span(buf).first(n), back) == Error::ok);
  CHECK(back == req);
  Payload pb{};
  REQUIRE(read_payload(back, pb) == Error::ok);
  CHECK(pb == p);
}

template <class Payload>
void check_response_round_trip(Opcode op, Status st, const Payload& p) {
  const Request req = make_request(op, 0xA5);
  Response rsp{};
  REQUIRE(make_response(req, st, p, rsp) == Error::ok);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_response(rsp, buf, n) == Error::ok);
  CHECK(n == kResponseOverhead + Payload::kWireSize);
  Response back{};
  REQUIRE(decode_response(std::span(buf).first(n), back) == Error::ok);
  CHECK(back == rsp);
  CHECK(back.opcode == op);
  CHECK(back.token == 0xA5);
  CHECK(back.status == st);
  Payload pb{};
  REQUIRE(read_payload(back, pb) == Error::ok);
  CHECK(pb == p);
}

DeviceInfo sample_info() {
  DeviceInfo info{};
  info.firmware_major = 1;
  info.firmware_minor = 2;
  info.firmware_patch = 3;
  info.serial = 0x1122334455667788ULL;
  info.hardware_revision = 4;
  info.pair_group = {0, 1, 2, 3, kPairUnused, kPairUnused, kPairUnused, kPairUnused};
  info.transports = transport_bit::usb_hid | transport_bit::can;
  info.protocol_minor = kProtocolMinor;
  info.features = feature_bit::fault_log;
  info.build_id = 0xCAFEF00D;
  info.boot_count = 123456;
  info.reset_cause = ResetCause::watchdog;
  return info;
}

}  // namespace

TEST_CASE("minor 1 additions: a minor-0 DeviceInfo still reads, the fault log round-trips and is checked") {
  // A version 1.0 band answers with the 29-byte DeviceInfo: the appended fields read as zero.
  const DeviceInfo full = sample_info();
  std::array<std::uint8_t, DeviceInfo::kWireSize> bytes{};
  ByteWriter w(bytes);
  full.write(w);
  REQUIRE(w.size() == DeviceInfo::kWireSize);
  Response old{};
  old.opcode = Opcode::get_device_info;
  old.length = static_cast<std::uint8_t>(DeviceInfo::kMinWireSize);
  std::copy_n(bytes.begin(), DeviceInfo::kMinWireSize, old.payload.begin());
  DeviceInfo read{};
  REQUIRE(read_payload(old, read) == Error::ok);
  CHECK(read.serial == full.serial);
  CHECK(read.protocol_minor == 0);
  CHECK(read.boot_count == 0);
  CHECK(read.reset_cause == ResetCause::unknown);
  old.length = static_cast<std::uint8_t>(DeviceInfo::kMinWireSize - 1);
  CHECK(read_payload(old, read) == Error::bad_length);

  FaultLog log{};
  log.count = 2;
  log.more = 1;
  log.dropped = 3;
  log.entries[0] = LogEntry{1000, FaultCode::sampler_restarted, 0, 1};
  log.entries[1] = LogEntry{1200, FaultCode::blocks_lost, 4, 12};
  check_response_round_trip(Opcode::get_log, Status::ok, log);
  Response rsp{};
  REQUIRE(make_response(make_request(Opcode::get_log, 1), Status::ok, log, rsp) == Error::ok);
  FaultLog bad{};
  rsp.payload[4 + 4] = 0;  // entry 0 with code none
  CHECK(read_payload(rsp, bad) == Error::bad_value);
  rsp.payload[4 + 4] = 1;
  rsp.payload[0] = 7;  // more entries than fit
  CHECK(read_payload(rsp, bad) == Error::bad_value);
  rsp.payload[0] = 2;
  rsp.payload[4 + 2 * 8] = 5;  // an unused slot that is not zero
  CHECK(read_payload(rsp, bad) == Error::bad_value);
  CHECK(is_known(Opcode::get_log));
  CHECK(is_known(Opcode::enter_bootloader));
}

TEST_CASE("every request payload round-trips") {
  check_request_round_trip(Opcode::time_sync, TimeSyncRequest{0xFEDCBA9876543210ULL});
  check_request_round_trip(Opcode::calibration_start,
                           CalibrationStart{CalibrationPhase::max_contraction, 0x000F, 5000});
  DeviceConfig cfg{};
  cfg.notch_hz = 60;
  cfg.envelope_mode = EnvelopeMode::moving_rms;
  cfg.curve = LevelCurve::power;
  cfg.curve_exponent_milli = 1500;
  check_request_round_trip(Opcode::set_config, cfg);
  check_request_round_trip(Opcode::reset, ResetRequest{ResetKind::factory_defaults});
}

TEST_CASE("every response payload round-trips") {
  check_response_round_trip(Opcode::get_device_info, Status::ok, sample_info());
  check_response_round_trip(Opcode::time_sync, Status::ok, TimeSyncResponse{1, 1000, 1010});
  check_response_round_trip(Opcode::get_stats, Status::ok, DeviceStats{1, 2, 3, 4, 5, 6, 7});
  check_response_round_trip(Opcode::calibration_status, Status::ok,
                            CalibrationStatus{CalibrationState::running, 2, 40, 0x00F0, 0x01});
  check_response_round_trip(Opcode::get_config, Status::ok, DeviceConfig{});
  check_response_round_trip(Opcode::set_config, Status::bad_value, SetConfigResult{ConfigField::notch_hz});
}

TEST_CASE("payload-less commands round-trip") {
  for (Opcode op : {Opcode::get_device_info, Opcode::get_stats, Opcode::calibration_abort, Opcode::calibration_status,
                    Opcode::get_config, Opcode::save_config}) {
    const Request req = make_request(op, 7);
    std::array<std::uint8_t, kMaxMessageSize> buf{};
    std::size_t n = 0;
    REQUIRE(encode_request(req, buf, n) == Error::ok);
    CHECK(n == kRequestOverhead);
    Request back{};
    REQUIRE(decode_request(std::span(buf).first(n), back) == Error::ok);
    CHECK(back == req);
    CHECK(is_known(back.opcode));
  }
}

TEST_CASE("unknown opcodes decode so the device can answer unknown_opcode") {
  Request req{};
  req.opcode = static_cast<Opcode>(0x7E);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_request(req, buf, n) == Error::ok);
  Request back{};
  REQUIRE(decode_request(std::span(buf).first(n), back) == Error::ok);
  CHECK_FALSE(is_known(back.opcode));
}

TEST_CASE("requests and responses are told apart") {
  const Request req = make_request(Opcode::get_config, 1);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_request(req, buf, n) == Error::ok);
  Response rsp{};
  CHECK(decode_response(std::span(buf).first(n), rsp) == Error::bad_type);
  REQUIRE(encode_response(make_response(req, Status::ok), buf, n) == Error::ok);
  Request back{};
  CHECK(decode_request(std::span(buf).first(n), back) == Error::bad_type);
}

TEST_CASE("command decoders: every truncation and every single-byte corruption is an error") {
  DeviceConfig cfg{};
  Request req{};
  REQUIRE(make_request(Opcode::set_config, 3, cfg, req) == Error::ok);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_request(req, buf, n) == Error::ok);
  for (std::size_t len = 0; len < n; ++len) {
    Request out{};
    CHECK(decode_request(std::span(buf).first(len), out) != Error::ok);
  }
  // CRC-16 detects every single-byte error, so no corruption may decode.
  std::size_t accepted = 0;
  tonus::test::for_each_byte_corruption(std::span(buf).first(n), [&](std::span<const std::uint8_t> bytes) {
    Request out{};
    if (decode_request(bytes, out) == Error::ok) ++accepted;
  });
  CHECK(accepted == 0);

  Response rsp{};
  REQUIRE(make_response(req, Status::ok, sample_info(), rsp) == Error::ok);
  REQUIRE(encode_response(rsp, buf, n) == Error::ok);
  for (std::size_t len = 0; len < n; ++len) {
    Response out{};
    CHECK(decode_response(std::span(buf).first(len), out) != Error::ok);
  }
  tonus::test::for_each_byte_corruption(std::span(buf).first(n), [&](std::span<const std::uint8_t> bytes) {
    Response out{};
    if (decode_response(bytes, out) == Error::ok) ++accepted;
  });
  CHECK(accepted == 0);
}

TEST_CASE("encoders refuse over-long payloads and unknown status codes") {
  Request req{};
  req.length = kMaxRequestPayload + 1;
  std::array<std::uint8_t, 128> buf{};
  std::size_t n = 0;
  CHECK(encode_request(req, buf, n) == Error::bad_length);
  Response rsp{};
  rsp.length = kMaxResponsePayload + 1;
  CHECK(encode_response(rsp, buf, n) == Error::bad_length);
  rsp.length = 0;
  rsp.status = static_cast<Status>(99);
  CHECK(encode_response(rsp, buf, n) == Error::bad_value);
  req.length = 0;
  std::array<std::uint8_t, 5> tiny{};
  CHECK(encode_request(req, tiny, n) == Error::buffer_too_small);
}

TEST_CASE("typed payload readers: short payloads, longer payloads and bad enums") {
  Request req{};
  REQUIRE(make_request(Opcode::calibration_start, 1, CalibrationStart{}, req) == Error::ok);
  CalibrationStart cs{};
  req.length = CalibrationStart::kWireSize - 1;
  CHECK(read_payload(req, cs) == Error::bad_length);
  req.length = CalibrationStart::kWireSize + 3;  // a newer minor version appended fields
  CHECK(read_payload(req, cs) == Error::ok);
  req.length = CalibrationStart::kWireSize;
  req.payload[0] = 9;  // no such phase
  CHECK(read_payload(req, cs) == Error::bad_value);
  req.payload[0] = 1;
  req.payload[1] = req.payload[2] = 0;  // empty channel mask
  CHECK(read_payload(req, cs) == Error::bad_value);

  Response rsp{};
  REQUIRE(make_response(req, Status::ok, TimeSyncResponse{0, 50, 40}, rsp) == Error::ok);
  TimeSyncResponse ts{};
  CHECK(read_payload(rsp, ts) == Error::bad_value);  // answered before received

  REQUIRE(make_request(Opcode::reset, 1, ResetRequest{}, req) == Error::ok);
  req.payload[0] = 2;
  ResetRequest rr{};
  CHECK(read_payload(req, rr) == Error::bad_value);
}

TEST_CASE("check_config names the first out-of-range field") {
  const DeviceConfig ok{};
  CHECK(check_config(ok, 4) == ConfigField::none);
  struct Case {
    void (*mutate)(DeviceConfig&);
    ConfigField field;
  };
  const Case cases[] = {
      {[](DeviceConfig& c) { c.sample_rate_hz = 50; }, ConfigField::sample_rate_hz},
      {[](DeviceConfig& c) { c.report_rate_hz = 0; }, ConfigField::report_rate_hz},
      {[](DeviceConfig& c) { c.report_rate_hz = 1001; }, ConfigField::report_rate_hz},
      {[](DeviceConfig& c) { c.highpass_dhz = 5; }, ConfigField::highpass_dhz},
      {[](DeviceConfig& c) { c.lowpass_dhz = 10000; }, ConfigField::lowpass_dhz},  // at Nyquist of 2 kHz
      {[](DeviceConfig& c) { c.lowpass_dhz = 150; }, ConfigField::lowpass_dhz},    // below the high-pass
      {[](DeviceConfig& c) { c.notch_hz = 55; }, ConfigField::notch_hz},
      {[](DeviceConfig& c) { c.notch_harmonics = 0; }, ConfigField::notch_harmonics},
      {[](DeviceConfig& c) { c.envelope_tau_ms = 1; }, ConfigField::envelope_tau_ms},
      {[](DeviceConfig& c) { c.pair_group[2] = 4; }, ConfigField::pair_group},
      {[](DeviceConfig& c) { c.dead_band = 0x8000; }, ConfigField::dead_band},
      {[](DeviceConfig& c) { c.hysteresis = 0x4001; }, ConfigField::hysteresis},
      {[](DeviceConfig& c) { c.curve_exponent_milli = 50; }, ConfigField::curve_exponent_milli},
      {[](DeviceConfig& c) { c.can_node_id = 32; }, ConfigField::can_node_id},
  };
  for (const Case& c : cases) {
    DeviceConfig cfg{};
    c.mutate(cfg);
    CAPTURE(to_string(c.field));
    CHECK(check_config(cfg, 4) == c.field);
  }
  DeviceConfig low{};
  low.sample_rate_hz = 200;  // a Myo-class band: no 450 Hz low-pass possible
  low.report_rate_hz = 100;
  CHECK(check_config(low, 4) == ConfigField::lowpass_dhz);
  low.lowpass_dhz = 0;
  CHECK(check_config(low, 4) == ConfigField::none);
}
