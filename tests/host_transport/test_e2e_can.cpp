// End to end over the simulated CAN link: struct can_frame datagrams, the
// stream reassembled by the host, segmented commands, heartbeats, candump log.
#include <doctest/doctest.h>

#include <chrono>
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
  std::uint32_t first_time = 0, last_time = 0, period_us = 0;
  int bad_steps = 0;
  const auto on_stream = [&](const proto::StreamMessage& m) {
    if (cycles == 0) first_time = m.device_time_us;
    if (cycles == 1) period_us = m.device_time_us - last_time;  // the report period (default rate)
    if (cycles > 0) {
      if (m.sequence != next_seq) ++gaps;
      // One period per report, 1 ms more across the one lost 1 ms block.
      const std::uint32_t step = m.device_time_us - last_time;
      if (step != period_us && !(step == period_us + 1000 && (m.status & proto::status_bit::block_lost) != 0)) {
        ++bad_steps;
      }
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
    // Half a second in (the transaction eats the heartbeats that come meanwhile: keep clear of them).
    if (!asked && cycles > 1 && last_time - first_time >= 500000) {
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
  REQUIRE(period_us > 0);
  CHECK(cycles == 3000000 / period_us - 1);  // one 1 ms block was lost, and with it one report
  CHECK(lost_flags == 1);
  CHECK(off == 0b100);
  CHECK(heartbeats == 3);
  CHECK(link.assembler().incomplete_cycles() == 0);
  CHECK(link.decode_errors() == 0);
  CHECK(sim.wait(5s) == 0);

  // The candump log parses line by line and holds the whole conversation.
  // Its times are Unix times, as candump writes them, so log2asc and other
  // tools keep one time base; and they never go back.
  const auto unix_now_us = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
  std::ifstream in(log);
  std::string line;
  std::size_t lines = 0, requests = 0;
  std::uint64_t last_us = 0;
  while (std::getline(in, line)) {
    proto::candump::Record rec{};
    REQUIRE_MESSAGE(proto::candump::parse(line, rec) == proto::Error::ok, line);
    CHECK(rec.time_us + 60000000U > unix_now_us);  // within a minute of now (a --fast run runs ahead)
    CHECK(rec.time_us < unix_now_us + 60000000U);
    CHECK(rec.time_us >= last_us);
    last_us = rec.time_us;
    CHECK(rec.iface_name() == "vcan0");
    proto::can::Function f{};
    std::uint8_t node = 0;
    REQUIRE(proto::can::split_id(rec.frame.id, f, node));
    if (f == proto::can::Function::request) ++requests;
    ++lines;
  }
  CHECK(requests >= 2);
  CHECK(lines > 3 * (cycles - 1));
  std::filesystem::remove(log);
}
