#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "tonus/protocol/sequence.hpp"

using namespace tonus::proto;
using V = SequenceTracker::Verdict;

TEST_CASE("sequence numbers wrap without loss") {
  SequenceTracker t;
  CHECK(t.push(65534) == V::first);
  CHECK(t.push(65535) == V::in_order);
  CHECK(t.push(0) == V::in_order);
  CHECK(t.push(1) == V::in_order);
  CHECK(t.lost() == 0);
  CHECK(t.received() == 4);
}

TEST_CASE("a gap across the wrap is counted lost, and taken back when a late message arrives") {
  SequenceTracker t;
  t.push(65533);
  CHECK(t.push(2) == V::gap);  // 65534, 65535, 0, 1 missing
  CHECK(t.lost() == 4);
  CHECK(t.push(0) == V::late);
  CHECK(t.lost() == 3);
  CHECK(t.reordered() == 1);
  CHECK(t.push(0) == V::duplicate);
  CHECK(t.push(2) == V::duplicate);
  CHECK(t.duplicates() == 2);
  CHECK(t.lost() == 3);
}

TEST_CASE("messages older than the window are stale, large jumps resync") {
  SequenceTracker t;
  t.push(1000);
  t.push(1100);
  CHECK(t.lost() == 99);
  CHECK(t.push(1000 + 1) == V::stale);  // 99 behind, window is 64
  CHECK(t.stale() == 1);
  CHECK(t.push(40000) == V::resync);  // device restarted
  CHECK(t.resyncs() == 1);
  CHECK(t.lost() == 99);  // the jump is not loss
  CHECK(t.push(40001) == V::in_order);
}

TEST_CASE("a long shuffled stream is accounted exactly") {
  // Send 200000 numbers (three wraps), drop every 97th, swap neighbours every 53rd,
  // duplicate every 71st; the tracker must count exactly that.
  std::vector<std::uint32_t> order;
  std::uint64_t dropped = 0, dups = 0;
  for (std::uint32_t i = 0; i < 200000; ++i) {
    if (i % 97 == 5) {
      ++dropped;
      continue;
    }
    order.push_back(i);
    if (i % 71 == 3) {
      order.push_back(i);
      ++dups;
    }
  }
  std::uint64_t swaps = 0;
  for (std::size_t j = 0; j + 1 < order.size(); j += 53) {
    // Only swap a first delivery with a later number, so each swap is one late arrival.
    if (order[j] < order[j + 1] && (j == 0 || order[j - 1] != order[j])) {
      std::swap(order[j], order[j + 1]);
      ++swaps;
    }
  }
  SequenceTracker t;
  for (std::uint32_t i : order) t.push(static_cast<std::uint16_t>(i));
  CHECK(t.lost() == dropped);
  CHECK(t.duplicates() == dups);
  CHECK(t.reordered() == swaps);
  CHECK(t.stale() == 0);
  CHECK(t.resyncs() == 0);
}

TEST_CASE("device timestamps unwrap across the 32-bit wrap and tolerate small steps back") {
  TimestampUnwrapper u;
  CHECK(u.push(0xFFFFFC18U) == 0xFFFFFC18LL);  // 1 ms before the wrap
  CHECK(u.push(0xFFFFFFFFU) == 0xFFFFFFFFLL);
  CHECK(u.push(999U) == 0x100000000LL + 999);
  CHECK(u.push(500U) == 0x100000000LL + 500);  // a reordered report
  CHECK(u.push(2000U) == 0x100000000LL + 2000);
  // Three more full wraps in 1 s steps.
  std::int64_t expect = 0x100000000LL + 2000;
  std::uint32_t raw = 2000;
  for (int i = 0; i < 3 * 4295; ++i) {
    raw += 1000000U;
    expect += 1000000;
    REQUIRE(u.push(raw) == expect);
  }
  CHECK(u.latest() > 3 * 0x100000000LL);
}

namespace {

// Pushes `n` reports numbered from `start`, all of one boot; returns how many the tracker took as new.
std::uint64_t push_run(SequenceTracker& t, std::uint32_t start, std::uint32_t n, std::uint8_t epoch) {
  std::uint64_t taken = 0;
  for (std::uint32_t i = start; i < start + n; ++i) {
    const V v = t.push(static_cast<std::uint16_t>(i), epoch);
    if (v == V::first || v == V::in_order || v == V::gap || v == V::resync) ++taken;
  }
  return taken;
}

}  // namespace

TEST_CASE("a reboot within 4096 reports, told by the boot epoch, drops nothing (issue 10, defect 8)") {
  // The band reboots after n reports and numbers from 0 again. Without the epoch the
  // restarted numbers look older than the newest one and were dropped as stale or duplicates.
  for (const std::uint32_t n : {1U, 2U, 63U, 64U, 65U, 2000U, 4095U}) {
    CAPTURE(n);
    SequenceTracker t;
    CHECK(push_run(t, 0, n, 17) == n);
    CHECK(push_run(t, 0, 3000, 18) == 3000);  // the second boot
    CHECK(t.received() == n + 3000);
    CHECK(t.resyncs() == 1);
    CHECK(t.lost() == 0);
    CHECK(t.stale() == 0);
    CHECK(t.duplicates() == 0);
    CHECK(t.reordered() == 0);
  }
}

TEST_CASE("boot epoch: a reboot that restarts mid-number, and epochs that wrap") {
  SequenceTracker t;
  CHECK(push_run(t, 100, 50, 255) == 50);
  CHECK(push_run(t, 120, 10, 1) == 10);  // 255 -> 1: any change is a new boot, even to a lower value
  CHECK(t.push(130, 1) == V::in_order);
  CHECK(t.push(130, 1) == V::duplicate);  // within one boot the history still works
  CHECK(t.resyncs() == 1);
  CHECK(t.lost() == 0);
}

TEST_CASE("boot epoch 0 (an older device) keeps the version-1.0 bookkeeping") {
  SequenceTracker t;
  CHECK(push_run(t, 0, 2000, 0) == 2000);
  // Without an epoch a restart at 0 cannot be told from very late reports.
  CHECK(t.push(0, 0) == V::stale);
  CHECK(t.resyncs() == 0);
}

TEST_CASE("after a reconnect, a backward jump is taken as a restart, a forward one as loss") {
  SequenceTracker t;
  push_run(t, 0, 2000, 0);
  t.note_reconnect();
  CHECK(t.push(0, 0) == V::resync);  // the link was reopened: the band most likely rebooted
  CHECK(t.push(1, 0) == V::in_order);
  CHECK(t.resyncs() == 1);
  t.note_reconnect();
  CHECK(t.push(11, 0) == V::gap);  // the same boot went on while the link was down
  CHECK(t.lost() == 9);
  CHECK(t.resyncs() == 1);
  // Only the first report after the reconnect gets the benefit.
  CHECK(t.push(5, 0) == V::late);
}

TEST_CASE("a restart known out of band (CAN heartbeat) counts once and loses nothing") {
  SequenceTracker t;
  t.note_restart();  // before any report: nothing to restart
  CHECK(t.resyncs() == 0);
  push_run(t, 0, 1000, 0);
  t.note_restart();
  CHECK(t.push(0, 0) == V::first);
  CHECK(push_run(t, 1, 999, 0) == 999);
  CHECK(t.resyncs() == 1);
  CHECK(t.lost() == 0);
  CHECK(t.stale() + t.duplicates() == 0);
}
