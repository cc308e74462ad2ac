// protocol/tonus.dbc must describe exactly the frames the codec sends.
#include <doctest/doctest.h>

#include <array>
#include <ios>
#include <map>
#include <set>
#include <string>

#include "support/dbc.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/command.hpp"

using namespace tonus::proto;
using tonus::test::DbcMessage;
using tonus::test::read_dbc;

namespace {

constexpr std::uint8_t kNode = 1;  // the DBC is written for node 1

StreamMessage full_message() {
  StreamMessage m{};
  m.group_count = kMaxGroups;
  m.channel_count = kMaxChannels;
  m.sequence = 0xBEEF;
  m.device_time_us = 0xCAFEF00D;
  m.status = status_bit::calibrated | status_bit::watchdog_reset | status_bit::block_lost;
  m.electrode_off = 0x8001;
  m.saturation = 0x0FF0;
  m.artifact = 0x1234;
  for (std::size_t g = 0; g < kMaxGroups; ++g) m.levels[g] = static_cast<std::uint16_t>(0x1111 * (g + 1));
  for (std::size_t c = 0; c < kMaxChannels; ++c) m.envelopes[c] = static_cast<std::uint16_t>(0x0101 * (c + 3));
  return m;
}

// Physical value every DBC signal must decode to, per frame id.
std::map<std::uint32_t, std::map<std::string, double>> expected_signals(const StreamMessage& m) {
  std::map<std::uint32_t, std::map<std::string, double>> e;
  auto bit = [&](std::uint16_t b) { return (m.status & b) != 0 ? 1.0 : 0.0; };
  auto& st = e[can::make_id(can::Function::status, kNode)];
  st["Sequence"] = m.sequence;
  st["DeviceTime"] = m.device_time_us;
  st["Calibrated"] = bit(status_bit::calibrated);
  st["Calibrating"] = bit(status_bit::calibrating);
  st["WatchdogReset"] = bit(status_bit::watchdog_reset);
  st["ConfigDirty"] = bit(status_bit::config_dirty);
  st["BlockLost"] = bit(status_bit::block_lost);
  st["EnvelopesFollow"] = 1.0;  // the frame is encoded with envelopes (below)
  for (std::size_t g = 0; g < kMaxGroups; ++g) {
    const auto f = g < 4 ? can::Function::levels0 : can::Function::levels1;
    e[can::make_id(f, kNode)]["Level" + std::to_string(g)] = m.levels[g] / 65535.0;
  }
  const can::Function env[] = {can::Function::envelope0, can::Function::envelope1, can::Function::envelope2,
                               can::Function::envelope3};
  for (std::size_t c = 0; c < kMaxChannels; ++c) {
    e[can::make_id(env[c / 4], kNode)]["Envelope" + std::to_string(c)] = m.envelopes[c] / 32768.0;
  }
  auto& fl = e[can::make_id(can::Function::flags, kNode)];
  fl["ElectrodeOff"] = m.electrode_off;
  fl["Saturation"] = m.saturation;
  fl["Artifact"] = m.artifact;
  fl["ChannelCount"] = m.channel_count;
  fl["GroupCount"] = m.group_count;
  fl["SequenceLow"] = m.sequence & 0xFF;
  return e;
}

const DbcMessage& find(const std::vector<DbcMessage>& dbc, std::uint32_t id) {
  for (const DbcMessage& msg : dbc) {
    if (msg.id == id) return msg;
  }
  FAIL("frame id 0x" << std::hex << id << " missing from tonus.dbc");
  throw;  // unreachable
}

void check_frame(const DbcMessage& msg, const CanFrame& frame, const std::map<std::string, double>& expect) {
  CAPTURE(msg.name);
  CHECK(frame.dlc == msg.dlc);
  std::set<std::string> names;
  for (const auto& s : msg.signals) {
    CAPTURE(s.name);
    CHECK(s.little_endian);
    CHECK(s.start_bit + s.length <= 8 * msg.dlc);
    names.insert(s.name);
    const auto it = expect.find(s.name);
    REQUIRE_MESSAGE(it != expect.end(), "signal not produced by the codec");
    const double physical = static_cast<double>(s.raw(frame.payload())) * s.factor + s.offset;
    CHECK(physical == doctest::Approx(it->second).epsilon(1e-9));
  }
  for (const auto& field : expect) {
    CHECK_MESSAGE(names.count(field.first) == 1, "codec field missing: " << field.first);
  }
  // Signals of a frame never overlap.
  std::array<int, 64> owner{};
  for (const auto& s : msg.signals) {
    for (unsigned b = s.start_bit; b < s.start_bit + s.length; ++b) CHECK(owner[b]++ == 0);
  }
}

}  // namespace

TEST_CASE("tonus.dbc describes every stream frame with the codec's bit positions") {
  const auto dbc = read_dbc(std::string(TONUS_SOURCE_DIR) + "/protocol/tonus.dbc");
  const StreamMessage m = full_message();
  std::array<CanFrame, can::kMaxStreamFrames> frames{};
  std::size_t n = 0;
  REQUIRE(can::encode_stream(m, kNode, true, frames, n) == Error::ok);
  REQUIRE(n == can::kMaxStreamFrames);
  const auto expect = expected_signals(m);
  for (std::size_t i = 0; i < n; ++i) check_frame(find(dbc, frames[i].id), frames[i], expect.at(frames[i].id));
}

TEST_CASE("tonus.dbc describes the heartbeat and command segments") {
  const auto dbc = read_dbc(std::string(TONUS_SOURCE_DIR) + "/protocol/tonus.dbc");
  const can::Heartbeat hb{can::NodeState::calibrating, kProtocolVersion,
                          status_bit::calibrating | status_bit::config_dirty, 987654};
  const CanFrame f = can::encode_heartbeat(hb, kNode);
  check_frame(find(dbc, f.id), f,
              {{"State", 2},
               {"ProtocolVersion", kProtocolVersion},
               {"Calibrated", 0},
               {"Calibrating", 1},
               {"WatchdogReset", 0},
               {"ConfigDirty", 1},
               {"BlockLost", 0},
               {"Uptime", 987654}});

  std::array<std::uint8_t, 20> message{};
  for (std::size_t i = 0; i < message.size(); ++i) message[i] = static_cast<std::uint8_t>(0xA0 + i);
  for (can::Function fn : {can::Function::request, can::Function::response}) {
    std::array<CanFrame, can::kMaxSegments> segs{};
    std::size_t n = 0;
    REQUIRE(can::segment(message, fn, kNode, segs, n) == Error::ok);
    REQUIRE(n == 3);
    std::uint64_t data = 0;
    for (std::size_t j = 0; j < 7; ++j) data |= static_cast<std::uint64_t>(message[7 + j]) << (8 * j);
    check_frame(find(dbc, segs[1].id), segs[1],
                {{"SegmentIndex", 1}, {"SegmentCount", 3}, {"SegmentData", static_cast<double>(data)}});
  }
}

TEST_CASE("tonus.dbc lists no frame the codec does not send") {
  const auto dbc = read_dbc(std::string(TONUS_SOURCE_DIR) + "/protocol/tonus.dbc");
  for (const DbcMessage& msg : dbc) {
    can::Function f{};
    std::uint8_t node = 0;
    CAPTURE(msg.name);
    CHECK(can::split_id(msg.id, f, node));
    CHECK(node == kNode);
  }
  CHECK(dbc.size() == 11);
}
