// The paced thread's overrun policy with a target that stalls on purpose:
// a short stall is caught up tick by tick, a long one is skipped, and the
// schedule never drifts or spirals.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "tonus/host/daemon/physics_thread.hpp"

using namespace tonus::daemon;

namespace {

class StallingTarget final : public TickTarget {
 public:
  void tick(std::int64_t now_us) override {
    const std::uint64_t k = ticks.fetch_add(1);
    if (last_us > 0 && now_us <= last_us) ++non_increasing;
    last_us = now_us;
    if (k == 100) std::this_thread::sleep_for(std::chrono::milliseconds(25));    // long: skipped
    if (k == 300) std::this_thread::sleep_for(std::chrono::microseconds(2500));  // short: caught up
  }
  std::atomic<std::uint64_t> ticks{0};
  std::int64_t last_us = 0;
  int non_increasing = 0;
};

// 1 kHz, no real-time privileges asked (tests run unprivileged).
PacingConfig paced_at_1khz(int max_catch_up_ticks) {
  PacingConfig c;
  c.rate_hz = 1000.0;
  c.max_catch_up_ticks = max_catch_up_ticks;
  c.realtime_priority = 0;
  c.lock_memory = false;
  return c;
}

}  // namespace

TEST_CASE("pacing: a long stall is skipped, a short one caught up, the schedule never drifts or spirals") {
  StallingTarget target;
  PhysicsThread t(target, paced_at_1khz(4));
  const auto t0 = std::chrono::steady_clock::now();
  t.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  t.stop();
  const double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  MESSAGE(t.ticks() << " ticks and " << t.skipped() << " skipped in " << elapsed_ms << " ms; " << t.overruns()
                    << " overruns; longest catch-up " << t.longest_catch_up() << " ticks; wake-up late p99 "
                    << t.wake_late().quantile_us(0.99) << " us");
  CHECK(target.non_increasing == 0);   // every tick's time is a later deadline
  CHECK(t.overruns() >= 2);            // both stalls
  CHECK(t.overruns_from_cost() >= 2);  // ... each a tick that alone took longer than the period
  CHECK(t.overruns_from_cost() <= t.overruns());
  CHECK(t.skipped() >= 20);          // the 25 ms stall: its missed deadlines skipped, not replayed
  CHECK(t.longest_catch_up() <= 4);  // never more than max_catch_up_ticks back to back
  // Ticks run plus ticks skipped account for the elapsed time: no drift (a VM's scheduling slack beside).
  const double scheduled = static_cast<double>(t.ticks() + t.skipped());
  CHECK(scheduled <= elapsed_ms + 2.0);
  CHECK(scheduled >= 0.95 * elapsed_ms - 30.0);
}

namespace {

// Every tick costs one and a half periods: the thread falls further behind on
// each, which is what a starved thread on a loaded machine sees.
class SlowTarget final : public TickTarget {
 public:
  void tick(std::int64_t /*now_us*/) override {
    ticks.fetch_add(1);
    std::this_thread::sleep_for(std::chrono::microseconds(1500));
  }
  std::atomic<std::uint64_t> ticks{0};
};

}  // namespace

TEST_CASE("pacing: a thread kept behind on every tick never runs more than max_catch_up_ticks late ticks in a row") {
  SlowTarget target;
  PhysicsThread t(target, paced_at_1khz(3));
  t.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  t.stop();
  MESSAGE(t.ticks() << " ticks, " << t.skipped() << " skipped, longest catch-up " << t.longest_catch_up());
  CHECK(t.ticks() >= 20);
  CHECK(t.skipped() >= 20);          // each tick's overrun piles up until it is skipped
  CHECK(t.longest_catch_up() >= 1);  // late ticks did run back to back ...
  CHECK(t.longest_catch_up() <= 3);  // ... but never more than the bound
}
