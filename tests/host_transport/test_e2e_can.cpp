// End to end over the simulated CAN link: struct can_frame datagrams, the
// stream reassembled by the host, segmented commands, heartbeats, candump log.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "sim_process.hpp"
#include "tonus/host/transport/band_link.hpp"
#include "tonus/protocol/candump.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus;
using namespace std::chrono_literals;

TEST_CASE("CAN link: stream with scripted faults, commands, heartbeat and the candump log") {
  const std::string log =
      (std::filesystem::temp_directory_path() / ("tonus-can-" + std::to_string(::getpid()) + ".log")).string();
  test::SimProcess sim(
      {"--synthetic", "faults", "--seconds", "3", "--fast", "--quiet", "--can-fd", "4", "--candump", log});
  REQUIRE(sim.started());
  host::SeqpacketCanTransport transport(sim.take_can());
  host::CanBandLink link(transport, 1);

  std::uint64_t cycles = 0, heartbeats = 0, lost_flags = 0;
  std::uint16_t next_seq = 0, off = 0;
  int gaps = 0;
  std::uint32_t last_time = 0;
  int bad_steps = 0;
  const auto on_stream = [&](const proto::StreamMessage& m) {
    if (cycles > 0) {
      if (m.sequence != next_seq) ++gaps;
      // 1 ms per report, 2 ms across the one lost 1 ms block.
      const std::uint32_t step = m.device_time_us - last_time;
      if (step != 1000 && !(step == 2000 && (m.status & proto::status_bit::block_lost) != 0)) ++bad_steps;
    }
    next_seq = static_cast<std::uint16_t>(m.sequence + 1);
    last_time = m.device_time_us;
    off |= m.electrode_off;
    if ((m.status & proto::status_bit::block_lost) != 0) ++lost_flags;
    ++cycles;
  };
  bool asked = false;
  for (;;) {
    const host::LinkEvent e = link.poll(3000);
    if (e.kind == host::LinkEvent::Kind::closed || e.kind == host::LinkEvent::Kind::none) break;
    if (e.kind == host::LinkEvent::Kind::heartbeat) {
      ++heartbeats;
      CHECK(e.heartbeat.state == proto::can::NodeState::running);
    }
    if (e.kind == host::LinkEvent::Kind::stream) on_stream(e.stream);
    if (!asked && cycles == 500) {
      asked = true;
      auto rsp = link.transact(proto::make_request(proto::Opcode::get_device_info, 9), 2000, on_stream);
      REQUIRE(rsp.has_value());
      proto::DeviceInfo info{};
      REQUIRE(proto::read_payload(*rsp, info) == proto::Error::ok);
      CHECK((info.transports & proto::transport_bit::can) != 0);
      proto::Request ts{};
      REQUIRE(proto::make_request(proto::Opcode::time_sync, 10, proto::TimeSyncRequest{42}, ts) == proto::Error::ok);
      rsp = link.transact(ts, 2000, on_stream);
      REQUIRE(rsp.has_value());
      proto::TimeSyncResponse t{};
      REQUIRE(proto::read_payload(*rsp, t) == proto::Error::ok);
      CHECK(t.host_time_us == 42);
    }
  }
  CHECK(asked);
  CHECK(gaps == 0);
  CHECK(bad_steps == 0);
  CHECK(cycles == 2999);  // one 1 ms block (two samples, one report) was lost
  CHECK(lost_flags == 1);
  CHECK(off == 0b100);
  CHECK(heartbeats == 3);
  CHECK(link.assembler().incomplete_cycles() == 0);
  CHECK(link.decode_errors() == 0);
  CHECK(sim.wait(5s) == 0);

  // The candump log parses line by line and holds the whole conversation.
  std::ifstream in(log);
  std::string line;
  std::size_t lines = 0, requests = 0;
  while (std::getline(in, line)) {
    proto::candump::Record rec{};
    REQUIRE_MESSAGE(proto::candump::parse(line, rec) == proto::Error::ok, line);
    CHECK(rec.iface_name() == "vcan0");
    proto::can::Function f{};
    std::uint8_t node = 0;
    REQUIRE(proto::can::split_id(rec.frame.id, f, node));
    if (f == proto::can::Function::request) ++requests;
    ++lines;
  }
  CHECK(requests >= 2);
  CHECK(lines > 3 * 2999);
  std::filesystem::remove(log);
}
