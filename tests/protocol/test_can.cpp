#include <doctest/doctest.h>

#include <array>
#include <random>
#include <vector>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus::proto;
using namespace tonus::proto::can;

namespace {

StreamMessage make_message(std::uint8_t groups, std::uint8_t channels, std::uint16_t seq) {
  StreamMessage m{};
  m.group_count = groups;
  m.channel_count = channels;
  m.sequence = seq;
  m.device_time_us = 0xABCD0000U + seq;
  m.status = status_bit::calibrated | status_bit::config_dirty;
  m.electrode_off = static_cast<std::uint16_t>(1U << (channels - 1U));
  for (std::size_t g = 0; g < groups; ++g) m.levels[g] = static_cast<std::uint16_t>(1000 * (g + 1) + seq);
  for (std::size_t c = 0; c < channels; ++c) m.envelopes[c] = static_cast<std::uint16_t>(100 * (c + 1) + seq);
  return m;
}

std::vector<CanFrame> frames_of(const StreamMessage& m, std::uint8_t node, bool env) {
  std::array<CanFrame, kMaxStreamFrames> frames{};
  std::size_t n = 0;
  REQUIRE(encode_stream(m, node, env, frames, n) == Error::ok);
  return {frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(n)};
}

// Pushes frames, returns how many cycles completed.
int feed(StreamAssembler& a, const std::vector<CanFrame>& frames) {
  int complete_count = 0;
  for (const CanFrame& f : frames) {
    bool complete = false;
    a.push(f, complete);
    complete_count += complete ? 1 : 0;
  }
  return complete_count;
}

}  // namespace

TEST_CASE("CAN ids follow the documented plan") {
  CHECK(make_id(Function::status, 1) == 0x101);
  CHECK(make_id(Function::flags, 31) == 0x1FF);
  CHECK(make_id(Function::request, 5) == 0x605);
  CHECK(make_id(Function::response, 5) == 0x585);
  CHECK(make_id(Function::heartbeat, 0) == 0x700);
  Function f{};
  std::uint8_t node = 0;
  CHECK(split_id(0x1C7, f, node));
  CHECK(f == Function::envelope3);
  CHECK(node == 7);
  CHECK_FALSE(split_id(0x200, f, node));
  CHECK_FALSE(split_id(0x800, f, node));
  // Every stream id outranks every command id, which outrank the heartbeat.
  CHECK(make_id(Function::flags, 31) < make_id(Function::response, 0));
  CHECK(make_id(Function::request, 31) < make_id(Function::heartbeat, 0));
}

TEST_CASE("stream cycles round-trip for every count, with and without envelopes") {
  for (std::uint8_t g = 1; g <= kMaxGroups; ++g) {
    for (std::uint8_t c = 1; c <= kMaxChannels; ++c) {
      const StreamMessage m = make_message(g, c, static_cast<std::uint16_t>(g * 100 + c));
      StreamAssembler a(9);
      const auto with_env = frames_of(m, 9, true);
      CHECK(with_env.size() == 2 + (g + 3U) / 4U + (c + 3U) / 4U);
      for (const CanFrame& f : with_env) CHECK(f.dlc <= 8);
      REQUIRE(feed(a, with_env) == 1);
      CHECK(a.message() == m);
      CHECK(a.envelopes_fresh());

      // Next cycle without envelopes: the previous envelopes are held.
      StreamMessage m2 = make_message(g, c, static_cast<std::uint16_t>(m.sequence + 1));
      REQUIRE(feed(a, frames_of(m2, 9, false)) == 1);
      CHECK_FALSE(a.envelopes_fresh());
      m2.envelopes = m.envelopes;
      CHECK(a.message() == m2);
      CHECK(a.incomplete_cycles() == 0);
    }
  }
}

TEST_CASE("losing any frame of a cycle loses that cycle and nothing else") {
  const StreamMessage m1 = make_message(6, 16, 10);
  const StreamMessage m2 = make_message(6, 16, 11);
  const auto f1 = frames_of(m1, 2, true);
  const auto f2 = frames_of(m2, 2, true);
  for (std::size_t drop = 0; drop < f1.size(); ++drop) {
    CAPTURE(drop);
    StreamAssembler a(2);
    auto lossy = f1;
    lossy.erase(lossy.begin() + static_cast<std::ptrdiff_t>(drop));
    CHECK(feed(a, lossy) == 0);
    REQUIRE(feed(a, f2) == 1);
    CHECK(a.message() == m2);
    CHECK(a.incomplete_cycles() + a.stray_frames() >= 1);
  }
}

TEST_CASE("losing every envelope frame of a cycle loses the cycle, it does not pass for one sent without them") {
  for (const std::uint8_t channels : {std::uint8_t{4}, std::uint8_t{8}, std::uint8_t{16}}) {
    CAPTURE(int{channels});
    const StreamMessage m = make_message(4, channels, 20);
    auto lossy = frames_of(m, 3, true);
    const auto before = lossy.size();
    std::erase_if(lossy, [](const CanFrame& f) {
      Function fn{};
      std::uint8_t node = 0;
      return split_id(f.id, fn, node) && fn >= Function::envelope0 && fn <= Function::envelope3;
    });
    REQUIRE(lossy.size() < before);
    StreamAssembler a(3);
    CHECK(feed(a, lossy) == 0);  // before the fix: delivered, with the previous envelopes
    CHECK(a.incomplete_cycles() == 1);
    // A cycle really sent without envelopes is delivered, and the status comes through without the binding's bit.
    StreamAssembler b(3);
    CHECK(feed(b, frames_of(m, 3, false)) == 1);
    CHECK(b.message().status == m.status);
    CHECK_FALSE(b.envelopes_fresh());
    StreamAssembler c(3);
    CHECK(feed(c, frames_of(m, 3, true)) == 1);
    CHECK(c.message() == m);
    CHECK(c.envelopes_fresh());
  }
}

TEST_CASE("frames of two cycles never merge when closing and opening frames are lost") {
  const StreamMessage m1 = make_message(4, 8, 20);
  const StreamMessage m2 = make_message(4, 8, 21);
  auto f1 = frames_of(m1, 1, false);  // status, levels0, flags
  auto f2 = frames_of(m2, 1, true);   // status, levels0, env0, env1, flags
  std::vector<CanFrame> bus;
  bus.push_back(f1[0]);
  bus.push_back(f1[1]);  // cycle 1 loses its FLAGS
  bus.push_back(f2[2]);  // cycle 2 loses STATUS and LEVELS0
  bus.push_back(f2[3]);
  bus.push_back(f2[4]);
  StreamAssembler a(1);
  CHECK(feed(a, bus) == 0);
  CHECK(a.incomplete_cycles() == 1);
}

TEST_CASE("duplicated, stray, foreign and malformed frames") {
  const StreamMessage m = make_message(4, 8, 5);
  auto f = frames_of(m, 3, false);
  StreamAssembler a(3);
  SUBCASE("duplicate levels frame voids the cycle") {
    std::vector<CanFrame> bus = {f[0], f[1], f[1], f[2]};
    CHECK(feed(a, bus) == 0);
    CHECK(a.incomplete_cycles() == 1);
    CHECK(a.stray_frames() == 1);  // the FLAGS after the voided cycle
  }
  SUBCASE("frames of other nodes, extended and remote frames are ignored") {
    std::vector<CanFrame> bus;
    for (const CanFrame& x : frames_of(make_message(4, 8, 99), 4, true)) bus.push_back(x);
    CanFrame ext = f[1];
    ext.flags = CanFrame::kExtended;
    CanFrame rtr = f[1];
    rtr.flags = CanFrame::kRemote;
    CanFrame other{};
    other.id = 0x7E5;
    other.dlc = 8;
    bus.insert(bus.begin() + 1, {ext, rtr, other});
    for (const CanFrame& x : f) bus.push_back(x);
    CHECK(feed(a, bus) == 1);
    StreamMessage expect = m;
    expect.envelopes = {};  // this cycle carried none and none came before
    CHECK(a.message() == expect);
    CHECK(a.stray_frames() == 0);
  }
  SUBCASE("odd or oversized dlc is refused") {
    CanFrame bad = f[1];
    bad.dlc = 3;
    bool complete = false;
    CHECK(a.push(f[0], complete) == Error::ok);
    CHECK(a.push(bad, complete) == Error::bad_length);
    bad.dlc = 9;
    CHECK(a.push(bad, complete) == Error::bad_length);
  }
  SUBCASE("counts in FLAGS must match the levels frames") {
    std::vector<CanFrame> bus = f;
    bus[2].data[6] = static_cast<std::uint8_t>((5U << 4U) | 7U);  // claims 6 groups
    CHECK(feed(a, bus) == 0);
    CHECK(a.incomplete_cycles() == 1);
  }
}

TEST_CASE("every single-byte corruption of a cycle gives an error, nothing, or a consistent message") {
  const StreamMessage m = make_message(5, 12, 300);
  const auto clean = frames_of(m, 6, true);
  std::size_t delivered = 0;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    for (std::size_t b = 0; b < clean[i].dlc; ++b) {
      for (unsigned v = 0; v < 256; v += 7) {
        auto frames = clean;
        frames[i].data[b] = static_cast<std::uint8_t>(v);
        StreamAssembler a(6);
        if (feed(a, frames) == 1) {
          ++delivered;
          CHECK(validate(a.message()) == Error::ok);
        }
      }
    }
  }
  CHECK(delivered > 0);
}

TEST_CASE("heartbeat round-trips and rejects bad frames") {
  const Heartbeat hb{NodeState::calibrating, kProtocolVersion, status_bit::calibrating, 123456};
  const CanFrame f = encode_heartbeat(hb, 12);
  CHECK(f.id == 0x70C);
  Heartbeat back{};
  REQUIRE(decode_heartbeat(f, back) == Error::ok);
  CHECK(back == hb);
  CanFrame bad = f;
  bad.dlc = 7;
  CHECK(decode_heartbeat(bad, back) == Error::bad_length);
  bad = f;
  bad.data[0] = 4;
  CHECK(decode_heartbeat(bad, back) == Error::bad_value);
  bad = f;
  bad.id = 0x10C;
  CHECK(decode_heartbeat(bad, back) == Error::bad_type);
}

TEST_CASE("command messages of every length survive segmentation") {
  for (std::size_t len = 1; len <= kMaxMessageSize; ++len) {
    std::array<std::uint8_t, kMaxMessageSize> msg{};
    for (std::size_t i = 0; i < len; ++i) msg[i] = static_cast<std::uint8_t>(i * 31 + len);
    std::array<CanFrame, kMaxSegments> frames{};
    std::size_t n = 0;
    REQUIRE(segment(std::span(msg).first(len), Function::request, 4, frames, n) == Error::ok);
    CHECK(n == (len + 6) / 7);
    Reassembler r(Function::request, 4);
    bool complete = false;
    for (std::size_t i = 0; i < n; ++i) {
      CHECK_FALSE(complete);
      REQUIRE(r.push(frames[i], complete) == Error::ok);
    }
    REQUIRE(complete);
    REQUIRE(r.message().size() == len);
    for (std::size_t i = 0; i < len; ++i) CHECK(r.message()[i] == msg[i]);
  }
  std::array<std::uint8_t, kMaxMessageSize + 1> too_long{};
  std::array<CanFrame, kMaxSegments + 1> frames{};
  std::size_t n = 0;
  CHECK(segment(too_long, Function::request, 4, frames, n) == Error::bad_length);
  CHECK(segment(std::span(too_long).first(0), Function::request, 4, frames, n) == Error::bad_length);
  CHECK(segment(std::span(too_long).first(8), Function::status, 4, frames, n) == Error::bad_type);
}

TEST_CASE("reassembly: a missing, repeated or foreign segment voids the message, index 0 restarts") {
  Request req{};
  REQUIRE(make_request(Opcode::set_config, 8, DeviceConfig{}, req) == Error::ok);
  std::array<std::uint8_t, kMaxMessageSize> bytes{};
  std::size_t len = 0;
  REQUIRE(encode_request(req, bytes, len) == Error::ok);
  std::array<CanFrame, kMaxSegments> frames{};
  std::size_t n = 0;
  REQUIRE(segment(std::span(bytes).first(len), Function::request, 1, frames, n) == Error::ok);
  REQUIRE(n == 6);

  for (std::size_t skip = 0; skip < n; ++skip) {
    Reassembler r(Function::request, 1);
    bool complete = false;
    bool any_complete = false;
    for (std::size_t i = 0; i < n; ++i) {
      if (i == skip) continue;
      r.push(frames[i], complete);
      any_complete |= complete;
    }
    CHECK_FALSE(any_complete);
  }
  Reassembler r(Function::request, 1);
  bool complete = false;
  CHECK(r.push(frames[0], complete) == Error::ok);
  CHECK(r.push(frames[1], complete) == Error::ok);
  CHECK(r.push(frames[1], complete) == Error::out_of_order);
  // A restart with index 0 recovers.
  for (std::size_t i = 0; i < n; ++i) REQUIRE(r.push(frames[i], complete) == Error::ok);
  REQUIRE(complete);
  Request back{};
  REQUIRE(decode_request(r.message(), back) == Error::ok);
  CHECK(back == req);
  // Responses and other nodes' requests are not ours.
  Reassembler other(Function::response, 1);
  CHECK(other.push(frames[0], complete) == Error::ok);
  CHECK_FALSE(complete);
  CanFrame bad = frames[0];
  bad.data[0] = 0x00;  // zero segments
  CHECK(r.push(bad, complete) == Error::bad_value);
  bad.data[0] = 0xA0;  // ten segments: more than a message can need
  CHECK(r.push(bad, complete) == Error::bad_value);
  bad = frames[0];
  bad.dlc = 5;  // a short non-final segment
  CHECK(r.push(bad, complete) == Error::bad_length);
}

TEST_CASE("id base: the whole plan moves to 29-bit ids, clear of CANopen's 11-bit ones") {
  CHECK(can::valid_id_base(0));
  CHECK(can::valid_id_base(0x800));
  CHECK(can::valid_id_base(can::kMaxIdBase));
  CHECK_FALSE(can::valid_id_base(0x400));
  CHECK_FALSE(can::valid_id_base(0x20000000));
  constexpr std::uint32_t kBase = 0x12345000;
  StreamMessage m{};
  m.sequence = 77;
  m.levels = {1, 2, 3, 4, 0, 0};
  std::array<CanFrame, can::kMaxStreamFrames> frames{};
  std::size_t count = 0;
  REQUIRE(can::encode_stream(m, 3, true, frames, count, kBase) == Error::ok);
  can::StreamAssembler at_base(3, kBase), plain(3), other_base(3, kBase + 0x800);
  bool complete = false, plain_complete = false, other_complete = false;
  for (std::size_t k = 0; k < count; ++k) {
    CHECK((frames[k].flags & CanFrame::kExtended) != 0);
    CHECK(frames[k].id >= 0x800);  // never an 11-bit id
    can::Function f{};
    std::uint8_t node = 0;
    REQUIRE(can::split_frame(frames[k], kBase, f, node));
    CHECK(node == 3);
    CHECK_FALSE(can::split_frame(frames[k], 0, f, node));
    REQUIRE(at_base.push(frames[k], complete) == Error::ok);
    REQUIRE(plain.push(frames[k], plain_complete) == Error::ok);
    REQUIRE(other_base.push(frames[k], other_complete) == Error::ok);
  }
  CHECK(complete);
  CHECK(at_base.message().sequence == 77);
  CHECK_FALSE(plain_complete);  // a host on the 11-bit plan ignores them
  CHECK_FALSE(other_complete);

  const std::vector<std::uint8_t> msg{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  std::array<CanFrame, can::kMaxSegments> segs{};
  REQUIRE(can::segment(msg, can::Function::request, 3, segs, count, kBase) == Error::ok);
  can::Reassembler r(can::Function::request, 3, kBase), r0(can::Function::request, 3);
  bool done = false, done0 = false;
  for (std::size_t k = 0; k < count; ++k) {
    REQUIRE(r.push(segs[k], done) == Error::ok);
    REQUIRE(r0.push(segs[k], done0) == Error::ok);
  }
  CHECK(done);
  CHECK_FALSE(done0);
  CHECK(std::vector<std::uint8_t>(r.message().begin(), r.message().end()) == msg);
  const CanFrame hb = can::encode_heartbeat(can::Heartbeat{}, 3, kBase);
  can::Heartbeat out{};
  CHECK(can::decode_heartbeat(hb, out, kBase) == Error::ok);
  CHECK(can::decode_heartbeat(hb, out) == Error::bad_type);
  CHECK(can::encode_stream(m, 3, true, frames, count, kBase + 1) == Error::bad_value);

  DeviceConfig cfg{};
  cfg.can_id_base = kBase;
  CHECK(check_config(cfg, 4) == ConfigField::none);
  cfg.can_id_base = kBase + 0x10;
  CHECK(check_config(cfg, 4) == ConfigField::can_id_base);
}
