// The USB device core against a fake controller driver: a Linux-like
// enumeration, descriptors checked by an independent walk, the HID data path,
// bad requests, and the firmware core streaming through it.
#include <doctest/doctest.h>

#include <algorithm>

#include <string>
#include <vector>

#include "fake_board.hpp"
#include "tonus/protocol/hid_descriptor.hpp"
#include "tonus/usb/device_core.hpp"

using namespace tonus;
using namespace tonus::usb;

namespace {

struct FakeDcd final : Dcd {
  enum class Stage { none, data_in, data_out, status, stall };
  Stage last = Stage::none;
  std::vector<std::uint8_t> sent;
  bool zlp = false;
  std::size_t receive_length = 0;
  int address = -1;
  bool status_after_address = false;
  bool hid_open = false;
  bool in_busy = false;
  std::vector<std::vector<std::uint8_t>> hid_packets;

  void set_address(std::uint8_t a) override {
    address = a;
    status_after_address = false;
  }
  void configure_hid_endpoints(bool open) override { hid_open = open; }
  void ep0_send(std::span<const std::uint8_t> data, bool needs_zlp) override {
    sent.assign(data.begin(), data.end());
    zlp = needs_zlp;
    last = Stage::data_in;
  }
  void ep0_receive(std::size_t length) override {
    receive_length = length;
    last = Stage::data_out;
  }
  void ep0_status() override {
    if (address >= 0) status_after_address = true;
    last = Stage::status;
  }
  void ep0_stall() override { last = Stage::stall; }
  bool hid_send(std::span<const std::uint8_t> packet) override {
    if (in_busy || !hid_open) return false;
    hid_packets.emplace_back(packet.begin(), packet.end());
    return true;
  }
};

std::array<std::uint8_t, 8> setup(std::uint8_t type, std::uint8_t req, std::uint16_t value, std::uint16_t index,
                                  std::uint16_t length) {
  return {type,
          req,
          static_cast<std::uint8_t>(value),
          static_cast<std::uint8_t>(value >> 8U),
          static_cast<std::uint8_t>(index),
          static_cast<std::uint8_t>(index >> 8U),
          static_cast<std::uint8_t>(length),
          static_cast<std::uint8_t>(length >> 8U)};
}

std::string utf16(const std::vector<std::uint8_t>& d) {
  std::string s;
  for (std::size_t k = 2; k + 1 < d.size(); k += 2) s.push_back(static_cast<char>(d[k]));
  return s;
}

void enumerate(DeviceCore& core, FakeDcd& dcd) {
  core.on_bus_reset();
  core.on_setup(setup(0x80, 6, 0x0100, 0, 64));
  core.on_setup(setup(0x00, 5, 7, 0, 0));
  core.on_setup(setup(0x00, 9, 1, 0, 0));
  REQUIRE(dcd.hid_open);
}

}  // namespace

TEST_CASE("descriptors: an independent walk of the configuration") {
  CHECK(kDeviceDescriptor[0] == 18);
  CHECK(kDeviceDescriptor[7] == 64);
  CHECK((kDeviceDescriptor[8] | (kDeviceDescriptor[9] << 8)) == kVendorId);
  const auto& c = kConfigurationDescriptor;
  CHECK((c[2] | (c[3] << 8)) == static_cast<int>(c.size()));
  std::size_t pos = 0;
  int interfaces = 0, endpoints = 0, hid = 0;
  while (pos < c.size()) {
    const std::uint8_t len = c[pos], type = c[pos + 1];
    REQUIRE(len >= 2);
    REQUIRE(pos + len <= c.size());
    if (type == desc::interface) {
      ++interfaces;
      CHECK(c[pos + 4] == 2);     // endpoints
      CHECK(c[pos + 5] == 0x03);  // HID
    } else if (type == desc::hid) {
      ++hid;
      CHECK((c[pos + 7] | (c[pos + 8] << 8)) == static_cast<int>(proto::hid::kReportDescriptor.size()));
    } else if (type == desc::endpoint) {
      ++endpoints;
      CHECK((c[pos + 2] & 0x0F) == kHidEndpoint);
      CHECK(c[pos + 3] == 0x03);  // interrupt
      CHECK(c[pos + 4] == 64);
    }
    pos += len;
  }
  CHECK(pos == c.size());
  CHECK(interfaces == c[4]);
  CHECK(hid == 1);
  CHECK(endpoints == 2);
}

TEST_CASE("enumeration as Linux does it") {
  FakeDcd dcd;
  DeviceCore core(dcd, 0x0123456789ABCDEFULL);
  core.on_bus_reset();
  CHECK_FALSE(core.connected());

  core.on_setup(setup(0x80, 6, 0x0100, 0, 64));  // GET_DESCRIPTOR device, 64 bytes asked
  CHECK(dcd.last == FakeDcd::Stage::data_in);
  CHECK(dcd.sent == std::vector<std::uint8_t>(kDeviceDescriptor.begin(), kDeviceDescriptor.end()));
  CHECK_FALSE(dcd.zlp);

  core.on_setup(setup(0x00, 5, 7, 0, 0));  // SET_ADDRESS 7
  CHECK(dcd.address == 7);
  CHECK(dcd.status_after_address);

  core.on_setup(setup(0x80, 6, 0x0200, 0, 9));  // configuration header only
  CHECK(dcd.sent.size() == 9);
  core.on_setup(setup(0x80, 6, 0x0200, 0, 255));
  CHECK(dcd.sent.size() == kConfigurationSize);

  core.on_setup(setup(0x80, 6, 0x0300, 0, 255));
  CHECK(dcd.sent == std::vector<std::uint8_t>{4, 3, 0x09, 0x04});
  core.on_setup(setup(0x80, 6, 0x0302, 0x0409, 255));
  CHECK(utf16(dcd.sent) == "tonus EMG band");
  core.on_setup(setup(0x80, 6, 0x0303, 0x0409, 255));
  CHECK(utf16(dcd.sent) == "0123456789ABCDEF");
  core.on_setup(setup(0x80, 6, 0x0309, 0x0409, 255));
  CHECK(dcd.last == FakeDcd::Stage::stall);      // no such string
  core.on_setup(setup(0x80, 6, 0x0600, 0, 10));  // device qualifier: full-speed only
  CHECK(dcd.last == FakeDcd::Stage::stall);

  core.on_setup(setup(0x00, 9, 1, 0, 0));  // SET_CONFIGURATION 1
  CHECK(dcd.last == FakeDcd::Stage::status);
  CHECK(dcd.hid_open);
  CHECK(core.connected());
  core.on_setup(setup(0x80, 8, 0, 0, 1));
  CHECK(dcd.sent == std::vector<std::uint8_t>{1});

  core.on_setup(setup(0x21, 10, 0, 0, 0));  // HID SET_IDLE
  CHECK(dcd.last == FakeDcd::Stage::status);
  core.on_setup(setup(0x81, 6, 0x2200, 0, 255));  // report descriptor (interface recipient)
  CHECK(dcd.sent ==
        std::vector<std::uint8_t>(proto::hid::kReportDescriptor.begin(), proto::hid::kReportDescriptor.end()));
  proto::hid::DescriptorInfo info{};
  REQUIRE(proto::hid::parse_report_descriptor(dcd.sent, info) == proto::Error::ok);
  CHECK(info.report_bytes(proto::hid::kReportIdStream, proto::hid::ReportType::input) == 64);

  core.on_bus_reset();
  CHECK_FALSE(core.connected());
  CHECK_FALSE(dcd.hid_open);
}

TEST_CASE("bad control requests stall; replies never exceed wLength; ZLP when a short reply fills packets") {
  FakeDcd dcd;
  DeviceCore core(dcd, 1);
  core.on_bus_reset();
  core.on_setup(setup(0x40, 1, 0, 0, 0));  // vendor request
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup(0x00, 9, 2, 0, 0));  // configuration 2 does not exist
  CHECK(dcd.last == FakeDcd::Stage::stall);
  CHECK_FALSE(core.connected());
  core.on_setup(setup(0x00, 5, 200, 0, 0));  // address out of range
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup(0x21, 0x55, 0, 0, 0));  // unknown HID request
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup(0x21, 10, 0, 3, 0));  // SET_IDLE to interface 3
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup(0x80, 6, 0x0100, 0, 8));  // first 8 bytes of the device descriptor
  CHECK(dcd.sent.size() == 8);
  core.on_setup(setup(0xA1, 1, 0x0101, 0, 100));  // GET_REPORT: 64 bytes < 100 asked, a multiple of 64
  CHECK(dcd.sent.size() == 64);
  CHECK(dcd.zlp);
  core.on_setup(setup(0x21, 9, 0x0202, 0, 65));  // SET_REPORT longer than a report
  CHECK(dcd.last == FakeDcd::Stage::stall);
}

TEST_CASE("HID data path: input reports on EP1, output reports from EP1 OUT or SET_REPORT") {
  FakeDcd dcd;
  DeviceCore core(dcd, 1);
  proto::hid::Report r{};
  r[0] = 1;
  CHECK_FALSE(core.send_input(r));  // not configured
  enumerate(core, dcd);
  CHECK(core.send_input(r));
  REQUIRE(dcd.hid_packets.size() == 1);
  CHECK(dcd.hid_packets[0].size() == 64);
  dcd.in_busy = true;
  CHECK_FALSE(core.send_input(r));  // previous packet not yet polled: dropped, counted by the caller

  std::size_t length = 0;
  CHECK_FALSE(core.receive_output(r, length));
  const std::vector<std::uint8_t> out{2, 1, 0x20, 5, 0};
  core.on_hid_out(out);
  REQUIRE(core.receive_output(r, length));
  CHECK(length == out.size());
  CHECK(r[2] == 0x20);
  CHECK(r[10] == 0);

  core.on_setup(setup(0x21, 9, 0x0202, 0, 64));  // SET_REPORT(output, id 2) through EP0
  CHECK(dcd.last == FakeDcd::Stage::data_out);
  CHECK(dcd.receive_length == 64);
  std::vector<std::uint8_t> data(64, 0);
  data[0] = 2;
  data[1] = 9;
  core.on_ep0_data(data);
  CHECK(dcd.last == FakeDcd::Stage::status);
  REQUIRE(core.receive_output(r, length));
  CHECK(r[1] == 9);

  for (int k = 0; k < 20; ++k) core.on_hid_out(out);  // the main loop stalls
  CHECK(core.out_overflows() > 0);
  int drained = 0;
  while (core.receive_output(r, length)) ++drained;
  CHECK(drained == 7);  // queue of 8, one slot kept free
}

TEST_CASE("the firmware core streams and answers through the USB stack") {
  FakeDcd dcd;
  DeviceCore core(dcd, 99);
  fw::SynthSpec spec;
  spec.scenario = fw::Scenario::rest;
  spec.seconds = 1.0F;
  test::Bench b(spec);
  hal::Board board{b.sampler, b.clock, b.storage, b.led, b.watchdog, b.system, &core, nullptr, 99, 1};
  fw::Device dev(board);
  dev.boot();
  b.run_for(dev, 0.05F);
  CHECK(dcd.hid_packets.empty());  // not enumerated: nothing sent, nothing counted as dropped
  enumerate(core, dcd);
  b.run_for(dev, 0.05F);
  CHECK(dcd.hid_packets.size() == 50);
  proto::StreamMessage m{};
  CHECK(proto::hid::unpack_stream(dcd.hid_packets.back(), m) == proto::Error::ok);

  proto::hid::Report req{};
  REQUIRE(proto::hid::pack_request(proto::make_request(proto::Opcode::get_device_info, 5), req) == proto::Error::ok);
  core.on_hid_out(req);
  dcd.hid_packets.clear();
  b.run_for(dev, 0.002F);
  bool answered = false;
  for (const auto& p : dcd.hid_packets) {
    proto::Response rsp{};
    if (p[0] == proto::hid::kReportIdResponse && proto::hid::unpack_response(p, rsp) == proto::Error::ok) {
      answered = rsp.token == 5 && rsp.status == proto::Status::ok;
    }
  }
  CHECK(answered);
}

TEST_CASE("GET_REPORT over EP0 returns the last input report of that id, not zeros") {
  FakeDcd dcd;
  DeviceCore core(dcd, 1);
  enumerate(core, dcd);
  proto::hid::Report stream{};
  stream[0] = proto::hid::kReportIdStream;
  for (std::size_t k = 1; k < stream.size(); ++k) stream[k] = static_cast<std::uint8_t>(k * 3U);
  REQUIRE(core.send_input(stream));
  dcd.sent.clear();
  core.on_setup(setup(0xA1, 1, 0x0101, 0, 64));  // GET_REPORT, input, id 1
  REQUIRE(dcd.sent.size() == 64);
  CHECK(std::equal(stream.begin(), stream.end(), dcd.sent.begin()));  // before: id + zeros
  // A response report is kept apart from the stream's.
  proto::hid::Report response{};
  response[0] = proto::hid::kReportIdResponse;
  response[5] = 0x5A;
  REQUIRE(core.send_input(response));
  dcd.sent.clear();
  core.on_setup(setup(0xA1, 1, 0x0103, 0, 64));
  REQUIRE(dcd.sent.size() == 64);
  CHECK(dcd.sent[5] == 0x5A);
  dcd.sent.clear();
  core.on_setup(setup(0xA1, 1, 0x0101, 0, 64));
  CHECK(std::equal(stream.begin(), stream.end(), dcd.sent.begin()));
  // Feature reports and unknown ids do not exist: stalled.
  core.on_setup(setup(0xA1, 1, 0x0301, 0, 64));
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup(0xA1, 1, 0x0107, 0, 64));
  CHECK(dcd.last == FakeDcd::Stage::stall);
}
