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
#include "usb_setup.hpp"

using namespace tonus;
using namespace tonus::usb;
using tonus::test::setup_packet;

namespace {

// Like the real controller, EP1 IN holds one packet until the host's IN token
// takes it, once per 1 ms frame (host_poll): never more than one per frame.
struct FakeDcd final : Dcd {
  enum class Stage { none, data_in, data_out, status, stall };
  Stage last = Stage::none;
  std::vector<std::uint8_t> sent;
  bool zlp = false;
  std::size_t receive_length = 0;
  int address = -1;
  bool status_after_address = false;
  bool hid_open = false;
  bool in_halt = false;
  bool out_halt = false;
  int toggle_resets = 0;
  std::vector<std::uint8_t> loaded;                    // in EP1's TX FIFO, not yet polled
  std::vector<std::vector<std::uint8_t>> hid_packets;  // taken by the host

  void set_address(std::uint8_t a) override {
    address = a;
    status_after_address = false;
  }
  void configure_hid_endpoints(bool open) override {
    hid_open = open;
    loaded.clear();
  }
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
    if (!loaded.empty() || !hid_open || in_halt) return false;
    loaded.assign(packet.begin(), packet.end());
    return true;
  }
  [[nodiscard]] bool hid_busy() const override { return !loaded.empty(); }
  void hid_halt(bool in, bool halt) override {
    (in ? in_halt : out_halt) = halt;
    if (!halt) ++toggle_resets;
  }
  // The host's IN token of one frame: takes the loaded packet, if any.
  void host_poll() {
    if (loaded.empty() || in_halt) return;
    hid_packets.push_back(loaded);
    loaded.clear();
  }
  // A chip reset: whatever sat in the FIFO never leaves.
  void chip_reset() {
    loaded.clear();
    hid_open = false;
  }
};

std::string utf16(const std::vector<std::uint8_t>& d) {
  std::string s;
  for (std::size_t k = 2; k + 1 < d.size(); k += 2) s.push_back(static_cast<char>(d[k]));
  return s;
}

void enumerate(DeviceCore& core, FakeDcd& dcd) {
  core.on_bus_reset();
  core.on_setup(setup_packet(0x80, 6, 0x0100, 0, 64));
  core.on_setup(setup_packet(0x00, 5, 7, 0, 0));
  core.on_setup(setup_packet(0x00, 9, 1, 0, 0));
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

  core.on_setup(setup_packet(0x80, 6, 0x0100, 0, 64));  // GET_DESCRIPTOR device, 64 bytes asked
  CHECK(dcd.last == FakeDcd::Stage::data_in);
  CHECK(dcd.sent == std::vector<std::uint8_t>(kDeviceDescriptor.begin(), kDeviceDescriptor.end()));
  CHECK_FALSE(dcd.zlp);

  core.on_setup(setup_packet(0x00, 5, 7, 0, 0));  // SET_ADDRESS 7
  CHECK(dcd.address == 7);
  CHECK(dcd.status_after_address);

  core.on_setup(setup_packet(0x80, 6, 0x0200, 0, 9));  // configuration header only
  CHECK(dcd.sent.size() == 9);
  core.on_setup(setup_packet(0x80, 6, 0x0200, 0, 255));
  CHECK(dcd.sent.size() == kConfigurationSize);

  core.on_setup(setup_packet(0x80, 6, 0x0300, 0, 255));
  CHECK(dcd.sent == std::vector<std::uint8_t>{4, 3, 0x09, 0x04});
  core.on_setup(setup_packet(0x80, 6, 0x0302, 0x0409, 255));
  CHECK(utf16(dcd.sent) == "tonus EMG band");
  core.on_setup(setup_packet(0x80, 6, 0x0303, 0x0409, 255));
  CHECK(utf16(dcd.sent) == "0123456789ABCDEF");
  core.on_setup(setup_packet(0x80, 6, 0x0309, 0x0409, 255));
  CHECK(dcd.last == FakeDcd::Stage::stall);             // no such string
  core.on_setup(setup_packet(0x80, 6, 0x0600, 0, 10));  // device qualifier: full-speed only
  CHECK(dcd.last == FakeDcd::Stage::stall);

  core.on_setup(setup_packet(0x00, 9, 1, 0, 0));  // SET_CONFIGURATION 1
  CHECK(dcd.last == FakeDcd::Stage::status);
  CHECK(dcd.hid_open);
  CHECK(core.connected());
  core.on_setup(setup_packet(0x80, 8, 0, 0, 1));
  CHECK(dcd.sent == std::vector<std::uint8_t>{1});

  core.on_setup(setup_packet(0x21, 10, 0, 0, 0));  // HID SET_IDLE
  CHECK(dcd.last == FakeDcd::Stage::status);
  core.on_setup(setup_packet(0x81, 6, 0x2200, 0, 255));  // report descriptor (interface recipient)
  CHECK(dcd.sent ==
        std::vector<std::uint8_t>(proto::hid::kReportDescriptor.begin(), proto::hid::kReportDescriptor.end()));
  proto::hid::DescriptorInfo info{};
  REQUIRE(proto::hid::parse_report_descriptor(dcd.sent, info) == proto::Error::ok);
  CHECK(info.report_bytes(proto::hid::kReportIdStream, proto::hid::ReportType::input) == 64);

  core.on_bus_reset();
  CHECK_FALSE(core.connected());
  CHECK_FALSE(dcd.hid_open);
}

TEST_CASE("bad control requests stall, replies never exceed wLength, ZLP when a short reply fills packets") {
  FakeDcd dcd;
  DeviceCore core(dcd, 1);
  core.on_bus_reset();
  core.on_setup(setup_packet(0x40, 1, 0, 0, 0));  // vendor request
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup_packet(0x00, 9, 2, 0, 0));  // configuration 2 does not exist
  CHECK(dcd.last == FakeDcd::Stage::stall);
  CHECK_FALSE(core.connected());
  core.on_setup(setup_packet(0x00, 5, 200, 0, 0));  // address out of range
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup_packet(0x21, 0x55, 0, 0, 0));  // unknown HID request
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup_packet(0x21, 10, 0, 3, 0));  // SET_IDLE to interface 3
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup_packet(0x80, 6, 0x0100, 0, 8));  // first 8 bytes of the device descriptor
  CHECK(dcd.sent.size() == 8);
  core.on_setup(setup_packet(0xA1, 1, 0x0101, 0, 100));  // GET_REPORT: 64 bytes < 100 asked, a multiple of 64
  CHECK(dcd.sent.size() == 64);
  CHECK(dcd.zlp);
  core.on_setup(setup_packet(0x21, 9, 0x0202, 0, 65));  // SET_REPORT longer than a report
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
  CHECK(dcd.hid_busy());
  dcd.host_poll();
  REQUIRE(dcd.hid_packets.size() == 1);
  CHECK(dcd.hid_packets[0].size() == 64);
  CHECK(core.idle());
  r[0] = 9;
  CHECK_FALSE(core.send_input(r));  // not an input report id

  std::size_t length = 0;
  CHECK_FALSE(core.receive_output(r, length));
  const std::vector<std::uint8_t> out{2, 1, 0x20, 5, 0};
  core.on_hid_out(out);
  REQUIRE(core.receive_output(r, length));
  CHECK(length == out.size());
  CHECK(r[2] == 0x20);
  CHECK(r[10] == 0);

  core.on_setup(setup_packet(0x21, 9, 0x0202, 0, 64));  // SET_REPORT(output, id 2) through EP0
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

namespace {

// The firmware core on the USB stack, the host polling EP1 once per 1 ms block.
struct UsbBench {
  explicit UsbBench(float seconds, fw::Scenario scenario = fw::Scenario::rest) : b(spec(seconds, scenario)) {
    b.after_pass = [this] { dcd.host_poll(); };
  }
  static fw::SynthSpec spec(float seconds, fw::Scenario scenario) {
    fw::SynthSpec s;
    s.scenario = scenario;
    s.seconds = seconds;
    return s;
  }
  hal::Board board() {
    return hal::Board{b.sampler, b.clock, b.storage, b.led, b.watchdog, b.system, &core, nullptr, 99, 1};
  }

  std::vector<proto::StreamMessage> streams() const {
    std::vector<proto::StreamMessage> out;
    for (const auto& p : dcd.hid_packets) {
      proto::StreamMessage m{};
      if (p[0] == proto::hid::kReportIdStream && proto::hid::unpack_stream(p, m) == proto::Error::ok) out.push_back(m);
    }
    return out;
  }
  std::vector<proto::Response> responses() const {
    std::vector<proto::Response> out;
    for (const auto& p : dcd.hid_packets) {
      proto::Response r{};
      if (p[0] == proto::hid::kReportIdResponse && proto::hid::unpack_response(p, r) == proto::Error::ok)
        out.push_back(r);
    }
    return out;
  }
  void request(proto::Opcode op, std::uint8_t token) {
    proto::hid::Report req{};
    REQUIRE(proto::hid::pack_request(proto::make_request(op, token), req) == proto::Error::ok);
    core.on_hid_out(req);
  }

  FakeDcd dcd;
  DeviceCore core{dcd, 99};
  test::Bench b;
};

// Stream reports received in order with no sequence gap.
bool contiguous(const std::vector<proto::StreamMessage>& s) {
  for (std::size_t k = 1; k < s.size(); ++k) {
    if (static_cast<std::uint16_t>(s[k].sequence - s[k - 1].sequence) != 1) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("the firmware core streams and answers through the USB stack") {
  UsbBench u(1.0F);
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  u.b.run_for(dev, 0.05F);
  CHECK(u.dcd.hid_packets.empty());  // not enumerated: nothing sent, nothing counted as dropped
  enumerate(u.core, u.dcd);
  u.b.run_for(dev, 0.05F);
  CHECK(u.streams().size() == 25);  // 50 ms at the default 500 Hz
  u.request(proto::Opcode::get_device_info, 5);
  u.dcd.hid_packets.clear();
  u.b.run_for(dev, 0.002F);
  const auto r = u.responses();
  REQUIRE(r.size() == 1);
  CHECK(r[0].token == 5);
  CHECK(r[0].status == proto::Status::ok);
}

TEST_CASE("one IN packet per frame: 149 commands in 1.5 s cost no stream report at the default rate") {
  // The audit's case: with the stream at 1 kHz every response displaced a
  // report (149 of 1,500 lost). Now the reports and the answers share the frames.
  UsbBench u(2.0F, fw::Scenario::ramp);
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  enumerate(u.core, u.dcd);
  u.b.run_for(dev, 0.01F);
  u.dcd.hid_packets.clear();
  const std::uint32_t sent_before = dev.stats().reports_sent;
  for (int k = 0; k < 1500; ++k) {
    if (k % 10 == 3 && k / 10 < 149) u.request(proto::Opcode::get_stats, static_cast<std::uint8_t>(k / 10));
    REQUIRE(u.b.step(dev));
  }
  u.b.run_for(dev, 0.004F);  // the last answer and report leave
  const auto s = u.streams();
  const auto r = u.responses();
  CHECK(r.size() == 149);
  CHECK(s.size() == dev.stats().reports_sent - sent_before);
  CHECK(s.size() >= 750);
  CHECK(contiguous(s));
  CHECK(u.core.stream_superseded() == 0);
  CHECK(dev.stats().tx_dropped == 0);
  // Every frame carried at most one packet, by construction of the fake; and
  // each answer came within 2 ms of its request.
  CHECK(u.dcd.hid_packets.size() == s.size() + r.size());
}

TEST_CASE("at a 1 kHz report rate every response costs exactly one report, counted") {
  UsbBench u(1.0F);
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  enumerate(u.core, u.dcd);
  proto::DeviceConfig cfg = dev.config();
  cfg.report_rate_hz = 1000;
  proto::Request req{};
  REQUIRE(proto::make_request(proto::Opcode::set_config, 1, cfg, req) == proto::Error::ok);
  proto::hid::Report raw{};
  REQUIRE(proto::hid::pack_request(req, raw) == proto::Error::ok);
  u.core.on_hid_out(raw);
  u.b.run_for(dev, 0.01F);
  u.dcd.hid_packets.clear();
  const std::uint32_t sent_before = dev.stats().reports_sent;
  const std::uint32_t superseded_before = u.core.stream_superseded();
  for (int k = 0; k < 500; ++k) {
    if (k % 25 == 0) u.request(proto::Opcode::get_stats, static_cast<std::uint8_t>(k));
    REQUIRE(u.b.step(dev));
  }
  u.b.run_for(dev, 0.003F);
  const auto s = u.streams();
  const std::uint32_t superseded = u.core.stream_superseded() - superseded_before;
  CHECK(u.responses().size() == 20);
  CHECK(superseded == 20);
  CHECK(s.size() + superseded == dev.stats().reports_sent - sent_before);
}

TEST_CASE("reset: the answer leaves before the band reboots") {
  UsbBench u(1.0F);
  int answered_before_reboot = -1;
  u.b.on_reset = [&] {
    answered_before_reboot = static_cast<int>(u.responses().size());
    u.dcd.chip_reset();  // a packet still in the FIFO dies with the chip
    u.core.on_bus_reset();
  };
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  enumerate(u.core, u.dcd);
  u.b.run_for(dev, 0.02F);
  proto::Request req{};
  REQUIRE(proto::make_request(proto::Opcode::reset, 7, proto::ResetRequest{proto::ResetKind::reboot}, req) ==
          proto::Error::ok);
  proto::hid::Report raw{};
  REQUIRE(proto::hid::pack_request(req, raw) == proto::Error::ok);
  for (int k = 0; k < 40; ++k) {  // the request lands at every phase of the 500 Hz report clock
    u.dcd.hid_packets.clear();
    answered_before_reboot = -1;
    const int reboots = u.b.reboots;
    enumerate(u.core, u.dcd);
    u.b.run_for(dev, 0.001F * static_cast<float>(1 + k % 3));
    u.core.on_hid_out(raw);
    for (int f = 0; f < 60 && u.b.reboots == reboots; ++f) REQUIRE(u.b.step(dev));
    REQUIRE(u.b.reboots == reboots + 1);
    CHECK(answered_before_reboot == 1);
    const auto r = u.responses();
    REQUIRE_FALSE(r.empty());
    CHECK(r[0].token == 7);
  }
}

TEST_CASE("suspend and resume: the configuration survives and the stream continues") {
  UsbBench u(1.0F);
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  enumerate(u.core, u.dcd);
  u.b.run_for(dev, 0.02F);
  u.core.on_suspend();  // the host sleeps: no IN tokens
  u.b.after_pass = nullptr;
  u.b.run_for(dev, 0.05F);
  CHECK_FALSE(u.core.connected());
  u.core.on_resume();
  u.b.after_pass = [&] { u.dcd.host_poll(); };
  u.dcd.hid_packets.clear();
  u.b.run_for(dev, 0.02F);
  CHECK(u.core.connected());
  CHECK(u.streams().size() >= 9);  // before: silent until a bus reset re-enumerated it
  CHECK(u.core.suspends() == 1);
  CHECK(u.core.resumes() == 1);
}

TEST_CASE("ENDPOINT_HALT stalls EP1 until cleared, GET_STATUS reports it, the toggle resets") {
  UsbBench u(1.0F);
  hal::Board board = u.board();
  fw::Device dev(board);
  dev.boot();
  enumerate(u.core, u.dcd);
  u.core.on_setup(setup_packet(0x02, 3, 0, 0x81, 0));  // SET_FEATURE(ENDPOINT_HALT) on EP1 IN
  CHECK(u.dcd.last == FakeDcd::Stage::status);
  CHECK(u.dcd.in_halt);
  u.core.on_setup(setup_packet(0x82, 0, 0, 0x81, 2));  // GET_STATUS(endpoint 0x81)
  CHECK(u.dcd.sent == std::vector<std::uint8_t>{1, 0});
  u.b.run_for(dev, 0.01F);
  CHECK(u.streams().empty());
  u.core.on_setup(setup_packet(0x02, 1, 0, 0x81, 0));  // CLEAR_FEATURE(ENDPOINT_HALT)
  CHECK_FALSE(u.dcd.in_halt);
  CHECK(u.dcd.toggle_resets == 1);
  u.core.on_setup(setup_packet(0x82, 0, 0, 0x81, 2));
  CHECK(u.dcd.sent == std::vector<std::uint8_t>{0, 0});
  u.b.run_for(dev, 0.01F);
  CHECK(u.streams().size() >= 4);
  u.core.on_setup(setup_packet(0x02, 3, 0, 0x01, 0));  // EP1 OUT
  CHECK(u.dcd.out_halt);
  u.core.on_setup(setup_packet(0x02, 3, 0, 0x85, 0));  // no such endpoint
  CHECK(u.dcd.last == FakeDcd::Stage::stall);
  u.core.on_setup(setup_packet(0x00, 3, 1, 0, 0));  // DEVICE_REMOTE_WAKEUP: not supported
  CHECK(u.dcd.last == FakeDcd::Stage::stall);
}

TEST_CASE("GET_REPORT over EP0 returns the last input report of that id, not zeros") {
  FakeDcd dcd;
  DeviceCore core(dcd, 1);
  enumerate(core, dcd);
  proto::hid::Report stream{};
  stream[0] = proto::hid::kReportIdStream;
  for (std::size_t k = 1; k < stream.size(); ++k) stream[k] = static_cast<std::uint8_t>(k * 3U);
  REQUIRE(core.send_input(stream));
  dcd.host_poll();
  dcd.sent.clear();
  core.on_setup(setup_packet(0xA1, 1, 0x0101, 0, 64));  // GET_REPORT, input, id 1
  REQUIRE(dcd.sent.size() == 64);
  CHECK(std::equal(stream.begin(), stream.end(), dcd.sent.begin()));  // before: id + zeros
  // A response report is kept apart from the stream's.
  proto::hid::Report response{};
  response[0] = proto::hid::kReportIdResponse;
  response[5] = 0x5A;
  REQUIRE(core.send_input(response));
  dcd.host_poll();
  dcd.sent.clear();
  core.on_setup(setup_packet(0xA1, 1, 0x0103, 0, 64));
  REQUIRE(dcd.sent.size() == 64);
  CHECK(dcd.sent[5] == 0x5A);
  dcd.sent.clear();
  core.on_setup(setup_packet(0xA1, 1, 0x0101, 0, 64));
  CHECK(std::equal(stream.begin(), stream.end(), dcd.sent.begin()));
  // Feature reports and unknown ids do not exist: stalled.
  core.on_setup(setup_packet(0xA1, 1, 0x0301, 0, 64));
  CHECK(dcd.last == FakeDcd::Stage::stall);
  core.on_setup(setup_packet(0xA1, 1, 0x0107, 0, 64));
  CHECK(dcd.last == FakeDcd::Stage::stall);
}
