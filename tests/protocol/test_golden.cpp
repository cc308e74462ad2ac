// The golden vectors of docs/protocol.md, rebuilt from the messages the
// document describes next to them.
#include <doctest/doctest.h>

#include <array>
#include <string>
#include <vector>

#include "support/golden.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/candump.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus::proto;
using tonus::test::golden_block;
using tonus::test::golden_bytes;
using tonus::test::to_hex;

namespace {

StreamMessage golden_stream() {
  StreamMessage m{};
  m.sequence = 0x1234;
  m.device_time_us = 0x89ABCDEF;
  m.status = status_bit::calibrated | status_bit::config_dirty;
  m.electrode_off = 0x0004;
  m.saturation = 0x0080;
  m.artifact = 0x0000;
  m.group_count = 4;
  m.channel_count = 8;
  m.boot_epoch = 0x2A;
  m.levels = {0x0000, 0x4000, 0x8000, 0xFFFF, 0, 0};
  for (std::size_t c = 0; c < 8; ++c) m.envelopes[c] = static_cast<std::uint16_t>(0x0100 * (c + 1));
  return m;
}

DeviceInfo golden_info() {
  DeviceInfo info{};
  info.firmware_major = 1;
  info.firmware_minor = 2;
  info.firmware_patch = 3;
  info.serial = 0x1122334455667788ULL;
  info.hardware_revision = 4;
  info.pair_group = {0, 1, 2, 3, kPairUnused, kPairUnused, kPairUnused, kPairUnused};
  info.transports = transport_bit::usb_hid | transport_bit::can;
  info.protocol_minor = 1;
  info.features = feature_bit::boot_epoch | feature_bit::fault_log | feature_bit::bootloader;
  info.build_id = 0x1a2b3c4d;
  info.boot_count = 17;
  info.reset_cause = ResetCause::software;
  return info;
}

template <class Encode, class Message>
std::vector<std::uint8_t> encoded(Encode encode, const Message& m) {
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode(m, buf, n) == Error::ok);
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)};
}

void check_bytes(const std::string& name, const std::vector<std::uint8_t>& actual) {
  const std::vector<std::uint8_t> expect = golden_bytes(name);
  INFO("golden:" << name << " in docs/protocol.md should read\n" << to_hex(actual));
  REQUIRE_FALSE(expect.empty());
  CHECK(expect == actual);
}

std::vector<std::string> candump_lines(std::span<const CanFrame> frames) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    candump::Record rec{};
    rec.time_us = 100 * i;
    candump::set_iface(rec, "can0");
    rec.frame = frames[i];
    std::array<char, candump::kMaxLine> buf{};
    std::size_t n = 0;
    REQUIRE(candump::format(rec, buf, n) == Error::ok);
    lines.emplace_back(buf.data(), n - 1);  // without the newline
  }
  return lines;
}

void check_lines(const std::string& name, const std::vector<std::string>& actual) {
  std::string joined;
  for (const std::string& l : actual) joined += l + "\n";
  INFO("golden:" << name << " in docs/protocol.md should read\n" << joined);
  CHECK(golden_block(name) == actual);
}

}  // namespace

TEST_CASE("golden: stream message") {
  const auto bytes = encoded(encode_stream, golden_stream());
  check_bytes("stream_4x8", bytes);
  StreamMessage back{};
  REQUIRE(decode_stream(golden_bytes("stream_4x8"), back) == Error::ok);
  CHECK(back == golden_stream());

  hid::Report report{};
  REQUIRE(hid::pack_stream(golden_stream(), report) == Error::ok);
  CHECK(report[0] == 0x01);
  for (std::size_t i = 0; i < bytes.size(); ++i) CHECK(report[1 + i] == bytes[i]);
}

TEST_CASE("golden: time-sync request") {
  Request req{};
  REQUIRE(make_request(Opcode::time_sync, 0x42, TimeSyncRequest{0x0102030405060708ULL}, req) == Error::ok);
  check_bytes("request_time_sync", encoded(encode_request, req));
}

TEST_CASE("golden: device-info response") {
  Response rsp{};
  REQUIRE(make_response(make_request(Opcode::get_device_info, 0x43), Status::ok, golden_info(), rsp) == Error::ok);
  check_bytes("response_device_info", encoded(encode_response, rsp));
}

TEST_CASE("golden: set-config request with the default configuration") {
  Request req{};
  REQUIRE(make_request(Opcode::set_config, 0x07, DeviceConfig{}, req) == Error::ok);
  check_bytes("request_set_config_default", encoded(encode_request, req));
}

TEST_CASE("golden: set-config refused") {
  Response rsp{};
  REQUIRE(make_response(make_request(Opcode::set_config, 0x08), Status::bad_value,
                        SetConfigResult{ConfigField::notch_hz}, rsp) == Error::ok);
  check_bytes("response_set_config_rejected", encoded(encode_response, rsp));
}

TEST_CASE("golden: HID report descriptor") {
  check_bytes("hid_report_descriptor", {hid::kReportDescriptor.begin(), hid::kReportDescriptor.end()});
}

TEST_CASE("golden: CAN stream cycle as a candump log") {
  std::array<CanFrame, can::kMaxStreamFrames> frames{};
  std::size_t n = 0;
  REQUIRE(can::encode_stream(golden_stream(), 1, true, frames, n) == Error::ok);
  check_lines("can_stream_4x8", candump_lines(std::span(frames).first(n)));
}

TEST_CASE("golden: CAN segmented time-sync request and heartbeat") {
  Request req{};
  REQUIRE(make_request(Opcode::time_sync, 0x42, TimeSyncRequest{0x0102030405060708ULL}, req) == Error::ok);
  const auto bytes = encoded(encode_request, req);
  std::array<CanFrame, can::kMaxSegments> frames{};
  std::size_t n = 0;
  REQUIRE(can::segment(bytes, can::Function::request, 1, frames, n) == Error::ok);
  check_lines("can_request_time_sync", candump_lines(std::span(frames).first(n)));

  const CanFrame hb = can::encode_heartbeat(
      can::Heartbeat{can::NodeState::running, kProtocolVersion, status_bit::calibrated, 60000}, 1);
  check_lines("can_heartbeat", candump_lines(std::span(&hb, 1)));
}
