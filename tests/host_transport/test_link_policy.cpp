// BandLink's stream policy through scripted transports: loss, duplicates,
// reordering and reboots counted exactly, and no report delivered twice.
#include <doctest/doctest.h>

#include <random>
#include <set>
#include <utility>

#include "fake_transports.hpp"
#include "tonus/protocol/can.hpp"

using namespace tonus;
using Kind = host::LinkEvent::Kind;

namespace {

struct Delivered {
  std::vector<std::pair<std::uint8_t, std::uint16_t>> fresh, late;  // (epoch, sequence)
  std::uint64_t restarted = 0;
};

Delivered drain(host::BandLink& link) {
  Delivered d;
  for (;;) {
    const host::LinkEvent e = link.poll(10);
    if (e.kind == Kind::closed) return d;
    if (e.kind == Kind::stream) {
      CHECK(e.stream.levels[0] == e.stream.sequence);  // the report itself, not a neighbour's
      CHECK(e.rx_host_us > 0);
      d.fresh.emplace_back(e.stream.boot_epoch, e.stream.sequence);
      if (e.restarted) ++d.restarted;
    }
    if (e.kind == Kind::late_stream) d.late.emplace_back(e.stream.boot_epoch, e.stream.sequence);
  }
}

}  // namespace

TEST_CASE("HID link: loss, duplicates and reordering are counted exactly, and nothing is delivered twice") {
  // 5000 reports: drop every 41st, duplicate every 37th (sometimes twice), swap neighbours every 29th,
  // and repeat a report from 100 back every 401st (beyond the 64-report window: stale).
  test::FakeHidTransport t;
  std::vector<std::uint16_t> order;
  std::uint64_t dropped = 0, dups = 0, stale = 0;
  for (std::uint16_t i = 0; i < 5000; ++i) {
    if (i % 41 == 7) {
      ++dropped;
      continue;
    }
    order.push_back(i);
    if (i % 37 == 3) {
      order.push_back(i);
      ++dups;
      if (i % 74 == 3) {
        order.push_back(i);
        ++dups;
      }
    }
    if (i % 401 == 200) {
      order.push_back(static_cast<std::uint16_t>(i - 100));
      ++stale;
    }
  }
  std::uint64_t swaps = 0;
  for (std::size_t j = 1; j + 2 < order.size(); j += 29) {
    // Swap only distinct, ascending, first deliveries: each swap is one late arrival.
    if (order[j] + 1 == order[j + 1] && order[j - 1] < order[j] && order[j + 2] > order[j + 1]) {
      std::swap(order[j], order[j + 1]);
      ++swaps;
    }
  }
  for (const std::uint16_t s : order) t.push(test::report(s, 9));
  host::HidBandLink link(t);
  const Delivered d = drain(link);
  const host::LinkStats s = link.stats();
  CHECK(s.reports == order.size());
  CHECK(s.lost == dropped);
  CHECK(s.duplicates == dups);
  CHECK(s.stale == stale);
  CHECK(s.late == swaps);
  CHECK(s.restarts == 0);
  CHECK(s.delivered == 5000 - dropped - swaps);
  CHECK(d.fresh.size() == s.delivered);
  CHECK(d.late.size() == s.late);
  // Never twice, and Kind::stream only ever moves forward.
  std::set<std::uint16_t> seen;
  for (const auto& [epoch, seq] : d.fresh) CHECK(seen.insert(seq).second);
  for (const auto& [epoch, seq] : d.late) CHECK(seen.insert(seq).second);
  CHECK(seen.size() == 5000 - dropped);
  for (std::size_t k = 1; k < d.fresh.size(); ++k) CHECK(d.fresh[k].second > d.fresh[k - 1].second);
}

TEST_CASE("HID link: a band that reboots after 1500 reports keeps every report of its next boot (defect 8)") {
  test::FakeHidTransport t;
  for (std::uint16_t i = 0; i < 1500; ++i) t.push(test::report(i, 200));
  for (std::uint16_t i = 0; i < 3000; ++i) t.push(test::report(i, 201));
  host::HidBandLink link(t);
  const Delivered d = drain(link);
  const host::LinkStats s = link.stats();
  CHECK(d.fresh.size() == 4500);
  CHECK(d.restarted == 1);
  CHECK(s.restarts == 1);
  CHECK(s.stale + s.duplicates + s.lost + s.late == 0);
}

TEST_CASE("HID link: bad reports are counted and never delivered") {
  test::FakeHidTransport t;
  t.push(test::report(0, 1));
  t.inbox.push_back({proto::hid::kReportIdStream, 9, 9, 9});  // wrong version, truncated
  t.inbox.push_back({0x7F});                                  // unknown report id
  t.inbox.push_back({});                                      // an empty read is a timeout, not an error
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k) {
    std::vector<std::uint8_t> junk(1 + static_cast<std::size_t>(rng() % 70));
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    junk[0] = proto::hid::kReportIdStream;
    t.inbox.push_back(junk);
  }
  t.push(test::report(1, 1));
  host::HidBandLink link(t);
  const Delivered d = drain(link);
  // Every read is either a decode error or a report (random bytes rarely make a valid one).
  CHECK(link.stats().decode_errors + link.stats().reports == 204);
  CHECK(link.stats().decode_errors >= 190);
  REQUIRE_FALSE(d.fresh.empty());
  CHECK(d.fresh.front() == std::make_pair(std::uint8_t{1}, std::uint16_t{0}));
}

TEST_CASE("CAN link: a heartbeat whose uptime went back marks a reboot, the stream after it is kept") {
  test::FakeCanTransport t;
  const auto cycle = [&](std::uint16_t seq) {
    std::array<proto::CanFrame, proto::can::kMaxStreamFrames> frames{};
    std::size_t n = 0;
    REQUIRE(proto::can::encode_stream(test::report(seq, 0), 1, false, frames, n) == proto::Error::ok);
    for (std::size_t k = 0; k < n; ++k) t.inbox.push_back(frames[k]);
  };
  const auto heartbeat = [&](std::uint32_t uptime_ms) {
    t.inbox.push_back(proto::can::encode_heartbeat(
        proto::can::Heartbeat{proto::can::NodeState::running, proto::kProtocolVersion, 0, uptime_ms}, 1));
  };
  heartbeat(0);
  for (std::uint16_t i = 0; i < 1000; ++i) cycle(i);
  heartbeat(1000);
  for (std::uint16_t i = 1000; i < 2000; ++i) cycle(i);
  heartbeat(3);  // rebooted: the boot heartbeat comes before the first cycle
  for (std::uint16_t i = 0; i < 1000; ++i) cycle(i);
  heartbeat(0xFFFFFF00U);  // (a forward jump, as if many heartbeats were lost)
  heartbeat(5);            // the 49.7-day wrap of uptime_ms: not a reboot
  host::CanBandLink link(t, 1);
  std::uint64_t reboots = 0, fresh = 0, restarted = 0;
  for (;;) {
    const host::LinkEvent e = link.poll(10);
    if (e.kind == Kind::closed) break;
    if (e.kind == Kind::heartbeat && e.restarted) ++reboots;
    if (e.kind == Kind::stream) {
      ++fresh;
      if (e.restarted) ++restarted;
    }
  }
  CHECK(reboots == 1);
  CHECK(fresh == 3000);
  CHECK(restarted == 1);
  CHECK(link.stats().restarts == 1);
  CHECK(link.stats().stale + link.stats().duplicates + link.stats().lost == 0);
}
