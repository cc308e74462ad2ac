#include "protocol_demo.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/candump.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/sequence.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::tools {

namespace {

using namespace tonus::proto;

// Starts close to the 16-bit wrap so that every demo run crosses it.
constexpr std::uint16_t kFirstSequence = 65000;
constexpr std::uint32_t kFirstDeviceTimeUs = 0xFFFF0000U;  // and the 32-bit time wrap

// A stand-in for the band until the firmware core exists: each group's
// co-contraction follows a slow ramp-and-hold, envelopes follow their pair.
StreamMessage synthetic_report(std::size_t k, unsigned rate_hz) {
  StreamMessage m{};
  m.sequence = static_cast<std::uint16_t>(kFirstSequence + k);
  m.device_time_us = kFirstDeviceTimeUs + static_cast<std::uint32_t>(k * 1000000U / rate_hz);
  m.status = status_bit::calibrated;
  m.group_count = 4;
  m.channel_count = 8;
  const double t = static_cast<double>(k) / rate_hz;
  for (std::size_t g = 0; g < m.group_count; ++g) {
    const double phase = 2.0 * std::numbers::pi * (0.25 * t + 0.2 * static_cast<double>(g));
    const double level = std::clamp(0.5 - 0.6 * std::cos(phase), 0.0, 1.0);
    m.levels[g] = static_cast<std::uint16_t>(std::lround(level * kLevelMax));
    for (std::size_t side = 0; side < 2; ++side) {
      const double env = 0.05 + 0.9 * level * (side == 0 ? 1.0 : 0.8);
      m.envelopes[2 * g + side] = static_cast<std::uint16_t>(std::lround(env * kEnvelopeOne));
    }
  }
  if (t > 1.0 && t < 1.5) m.electrode_off = 1U << 3U;  // a scripted electrode lift
  return m;
}

struct Tally {
  std::uint64_t sent = 0, delivered = 0, decoded = 0, mismatches = 0, decode_errors = 0;
  std::uint64_t lost = 0, duplicates = 0, reordered = 0;
  std::uint64_t expect_lost = 0, expect_duplicates = 0, expect_reordered = 0;
};

// Reference bookkeeping from the unwrapped report index, independent of the
// wrapping sequence numbers the tracker sees.
struct Reference {
  std::set<std::size_t> seen;
  std::size_t first = 0, newest = 0;
  std::uint64_t duplicates = 0, late = 0;
  void push(std::size_t index) {
    if (seen.empty()) first = newest = index;
    if (!seen.insert(index).second) {
      ++duplicates;
      return;
    }
    if (index < newest) ++late;
    newest = std::max(newest, index);
    first = std::min(first, index);
  }
  [[nodiscard]] std::uint64_t missing() const { return (newest - first + 1) - seen.size(); }
};

Tally run_hid(const DemoOptions& opt, std::size_t reports, std::mt19937_64& rng) {
  std::bernoulli_distribution drop(opt.loss), dup(opt.duplication), swap(opt.reorder);
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < reports; ++k) {
    if (drop(rng)) continue;
    order.push_back(k);
    if (dup(rng)) order.push_back(k);
  }
  for (std::size_t j = 0; j + 1 < order.size(); ++j) {
    if (swap(rng)) {
      std::swap(order[j], order[j + 1]);
      ++j;
    }
  }

  Tally t;
  t.sent = reports;
  Reference ref;
  SequenceTracker tracker;
  for (std::size_t k : order) {
    const StreamMessage sent = synthetic_report(k, opt.report_rate_hz);
    hid::Report report{};
    if (hid::pack_stream(sent, report) != Error::ok) {
      ++t.decode_errors;
      continue;
    }
    ++t.delivered;
    StreamMessage got{};
    if (hid::unpack_stream(report, got) != Error::ok) {
      ++t.decode_errors;
      continue;
    }
    ++t.decoded;
    if (!(got == sent)) ++t.mismatches;
    tracker.push(got.sequence);
    ref.push(k);
  }
  t.lost = tracker.lost();
  t.duplicates = tracker.duplicates();
  t.reordered = tracker.reordered();
  t.expect_lost = ref.missing();
  t.expect_duplicates = ref.duplicates;
  t.expect_reordered = ref.late;
  return t;
}

struct CanTally {
  std::uint64_t cycles = 0, frames_sent = 0, frames_dropped = 0;
  std::uint64_t complete = 0, expect_complete = 0, mismatches = 0, incomplete = 0, stray = 0, errors = 0;
  std::uint64_t lost = 0, expect_lost = 0;
};

CanTally run_can(const DemoOptions& opt, std::size_t reports, std::mt19937_64& rng, std::FILE* log) {
  std::bernoulli_distribution drop(opt.loss);
  CanTally t;
  can::StreamAssembler assembler(opt.can_node);
  SequenceTracker tracker;
  Reference ref;
  std::array<std::uint16_t, kMaxChannels> last_envelopes{};
  for (std::size_t k = 0; k < reports; ++k) {
    const StreamMessage sent = synthetic_report(k, opt.report_rate_hz);
    const bool with_env = opt.can_envelope_divider != 0 && k % opt.can_envelope_divider == 0;
    std::array<CanFrame, can::kMaxStreamFrames> frames{};
    std::size_t count = 0;
    if (can::encode_stream(sent, opt.can_node, with_env, frames, count) != Error::ok) {
      ++t.errors;
      continue;
    }
    ++t.cycles;
    bool cycle_intact = true;
    for (std::size_t i = 0; i < count; ++i) {
      ++t.frames_sent;
      if (drop(rng)) {
        ++t.frames_dropped;
        cycle_intact = false;
        continue;
      }
      if (log != nullptr) {
        candump::Record rec{};
        rec.time_us = 1700000000ULL * 1000000ULL + k * 1000000ULL / opt.report_rate_hz + i * 10U;
        candump::set_iface(rec, "vcan0");
        rec.frame = frames[i];
        std::array<char, candump::kMaxLine> line{};
        std::size_t n = 0;
        if (candump::format(rec, line, n) == Error::ok) std::fwrite(line.data(), 1, n, log);
      }
      bool complete = false;
      if (assembler.push(frames[i], complete) != Error::ok) continue;  // counted by the assembler
      if (!complete) continue;
      ++t.complete;
      StreamMessage expect = sent;
      if (!with_env) expect.envelopes = last_envelopes;
      if (!(assembler.message() == expect)) ++t.mismatches;
      tracker.push(assembler.message().sequence);
      ref.push(k);
    }
    if (cycle_intact) {
      ++t.expect_complete;
      if (with_env) last_envelopes = sent.envelopes;
    }
  }
  t.incomplete = assembler.incomplete_cycles();
  t.stray = assembler.stray_frames();
  t.lost = tracker.lost();
  t.expect_lost = ref.missing();
  return t;
}

struct CommandTally {
  std::uint64_t exchanges = 0, hid_ok = 0, can_ok = 0;
};

// Every command through both bindings, request and response, decoded back.
CommandTally run_commands(std::uint8_t node) {
  CommandTally t;
  DeviceConfig cfg{};
  cfg.notch_hz = 60;
  DeviceInfo info{};
  info.firmware_major = 0;
  info.firmware_minor = 1;
  info.serial = 0x0123456789ABCDEFULL;
  info.pair_group = cfg.pair_group;
  info.transports = transport_bit::usb_hid | transport_bit::can;

  struct Exchange {
    Request req;
    Response rsp;
  };
  std::vector<Exchange> exchanges;
  auto add = [&](const Request& req, const Response& rsp) { exchanges.push_back({req, rsp}); };
  Request req{};
  Response rsp{};
  std::uint8_t token = 1;

  req = make_request(Opcode::get_device_info, token++);
  make_response(req, Status::ok, info, rsp);
  add(req, rsp);
  make_request(Opcode::time_sync, token++, TimeSyncRequest{123456789}, req);
  make_response(req, Status::ok, TimeSyncResponse{123456789, 5000000, 5000012}, rsp);
  add(req, rsp);
  make_request(Opcode::calibration_start, token++, CalibrationStart{CalibrationPhase::rest, 0x00FF, 3000}, req);
  add(req, make_response(req, Status::ok));
  make_request(Opcode::set_config, token++, cfg, req);
  make_response(req, Status::ok, SetConfigResult{}, rsp);
  add(req, rsp);
  DeviceConfig bad = cfg;
  bad.notch_hz = 55;
  make_request(Opcode::set_config, token++, bad, req);
  make_response(req, Status::bad_value, SetConfigResult{check_config(bad, 4)}, rsp);
  add(req, rsp);
  req = make_request(Opcode::get_config, token++);
  make_response(req, Status::ok, cfg, rsp);
  add(req, rsp);
  req = make_request(Opcode::save_config, token++);
  add(req, make_response(req, Status::ok));

  for (const Exchange& ex : exchanges) {
    ++t.exchanges;
    // USB-HID: output report out, input report back.
    hid::Report out{};
    hid::Report in{};
    Request hreq{};
    Response hrsp{};
    if (hid::pack_request(ex.req, out) == Error::ok && hid::unpack_request(out, hreq) == Error::ok && hreq == ex.req &&
        hid::pack_response(ex.rsp, in) == Error::ok && hid::unpack_response(in, hrsp) == Error::ok && hrsp == ex.rsp) {
      ++t.hid_ok;
    }
    // CAN: segmented request and response frames.
    std::array<std::uint8_t, kMaxMessageSize> bytes{};
    std::array<CanFrame, can::kMaxSegments> frames{};
    std::size_t n = 0;
    std::size_t count = 0;
    can::Reassembler dev_rx(can::Function::request, node);
    can::Reassembler host_rx(can::Function::response, node);
    bool complete = false;
    Request creq{};
    Response crsp{};
    bool ok = encode_request(ex.req, bytes, n) == Error::ok &&
              can::segment(std::span(bytes).first(n), can::Function::request, node, frames, count) == Error::ok;
    for (std::size_t i = 0; ok && i < count; ++i) ok = dev_rx.push(frames[i], complete) == Error::ok;
    ok = ok && complete && decode_request(dev_rx.message(), creq) == Error::ok && creq == ex.req;
    ok = ok && encode_response(ex.rsp, bytes, n) == Error::ok &&
         can::segment(std::span(bytes).first(n), can::Function::response, node, frames, count) == Error::ok;
    complete = false;
    for (std::size_t i = 0; ok && i < count; ++i) ok = host_rx.push(frames[i], complete) == Error::ok;
    ok = ok && complete && decode_response(host_rx.message(), crsp) == Error::ok && crsp == ex.rsp;
    if (ok) ++t.can_ok;
  }
  return t;
}

bool check(bool ok, const char* what) {
  if (!ok) fmt::print("  FAIL: {}\n", what);
  return ok;
}

}  // namespace

int run_protocol_demo(const DemoOptions& opt) {
  const auto reports = static_cast<std::size_t>(std::llround(opt.seconds * opt.report_rate_hz));
  std::mt19937_64 rng(opt.seed);

  std::unique_ptr<std::FILE, int (*)(std::FILE*)> log(nullptr, &std::fclose);
  if (!opt.candump_path.empty()) {
    log.reset(std::fopen(opt.candump_path.c_str(), "w"));
    if (!log) {
      fmt::print(stderr, "tonus demo: cannot write candump log '{}'\n", opt.candump_path);
      return 2;
    }
  }

  fmt::print("tonus demo: {:.2f} s of simulated band stream at {} Hz (4 groups, 8 channels), seed {}\n", opt.seconds,
             opt.report_rate_hz, opt.seed);
  fmt::print("links drop {:.1f} %, duplicate {:.1f} %, reorder {:.1f} % of reports (CAN: drop per frame)\n\n",
             100 * opt.loss, 100 * opt.duplication, 100 * opt.reorder);

  const Tally hid = run_hid(opt, reports, rng);
  const CanTally can = run_can(opt, reports, rng, log.get());
  const CommandTally cmd = run_commands(opt.can_node);

  fmt::print("USB-HID stream (64-byte input reports, id 0x01)\n");
  fmt::print("  reports sent {:>7}   delivered {:>7}   decoded {:>7}   byte-exact {:>7}\n", hid.sent, hid.delivered,
             hid.decoded, hid.decoded - hid.mismatches);
  fmt::print("  host counted: lost {} (injected {}), duplicates {} (injected {}), reordered {} (injected {})\n",
             hid.lost, hid.expect_lost, hid.duplicates, hid.expect_duplicates, hid.reordered, hid.expect_reordered);
  fmt::print("CAN stream (node {}, envelopes every {} cycles)\n", opt.can_node, opt.can_envelope_divider);
  fmt::print("  cycles sent {:>7}   frames {:>7}   frames dropped {:>5}\n", can.cycles, can.frames_sent,
             can.frames_dropped);
  fmt::print("  cycles assembled {} (intact on the bus {}), exact {}, incomplete {}, stray frames {}\n", can.complete,
             can.expect_complete, can.complete - can.mismatches, can.incomplete, can.stray);
  fmt::print("  host counted lost cycles {} (expected {})\n", can.lost, can.expect_lost);
  fmt::print("Commands (request + response, both bindings)\n");
  fmt::print("  exchanges {}   HID round trips ok {}   CAN segmented round trips ok {}\n", cmd.exchanges, cmd.hid_ok,
             cmd.can_ok);
  if (log) fmt::print("CAN traffic written to {} (candump -l format)\n", opt.candump_path);

  bool ok = true;
  ok &= check(hid.mismatches == 0 && hid.decode_errors == 0, "HID reports decode to what was sent");
  ok &= check(
      hid.lost == hid.expect_lost && hid.duplicates == hid.expect_duplicates && hid.reordered == hid.expect_reordered,
      "HID loss/duplication/reordering counted as injected");
  ok &= check(can.errors == 0 && can.mismatches == 0, "CAN cycles decode to what was sent");
  ok &= check(can.complete == can.expect_complete, "every intact CAN cycle assembled, no broken one");
  ok &= check(can.lost == can.expect_lost, "CAN cycle loss counted");
  ok &= check(cmd.hid_ok == cmd.exchanges && cmd.can_ok == cmd.exchanges, "every command round trip");
  fmt::print("\n{}\n", ok ? "result: OK, every message accounted for" : "result: FAILED");
  return ok ? 0 : 1;
}

}  // namespace tonus::tools
