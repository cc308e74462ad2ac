// The physics thread: PhysicsCore::tick at a fixed rate, paced by absolute
// deadlines (clock_nanosleep TIMER_ABSTIME on CLOCK_MONOTONIC, the clock
// std::chrono::steady_clock reads), so sleeping never accumulates drift.
//
// Overruns: a tick that ends after the next tick's deadline is an overrun.
// Those whose own cost exceeded the period are counted apart: the rest woke
// late (the scheduler, or a virtual machine's host) or were catching up.
// The next ticks then run back to back to catch up, but never more than
// max_catch_up_ticks behind: beyond that the missed deadlines are skipped
// (counted) and the schedule restarts from now, so a stall (a page fault, a
// preempted core) can never grow into a spiral of late ticks.
//
// Real-time: SCHED_FIFO at realtime_priority and mlockall when permitted; a
// refusal is reported (RealtimeSetup) and the loop runs anyway.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "tonus/host/daemon/histogram.hpp"
#include "tonus/host/daemon/physics_core.hpp"

namespace tonus::daemon {

struct PacingConfig {
  double rate_hz = 1000.0;
  int max_catch_up_ticks = 4;
  int realtime_priority = 20;  // 0: do not try
  bool lock_memory = true;
};

struct RealtimeSetup {
  bool priority_set = false;
  bool memory_locked = false;
  std::string priority_error;  // why not (empty when set or not tried)
  std::string lock_error;
};

// The figures of one status interval, published by the physics thread.
struct IntervalFigures {
  std::uint64_t ticks = 0;
  double p50_us = 0.0, p99_us = 0.0, max_us = 0.0;
  std::uint64_t overruns = 0;
  double band_latency_p50_us = 0.0, band_latency_p99_us = 0.0;  // device sample -> tick
};

class PhysicsThread {
 public:
  PhysicsThread(TickTarget& core, const PacingConfig& config);
  ~PhysicsThread();
  PhysicsThread(const PhysicsThread&) = delete;
  PhysicsThread& operator=(const PhysicsThread&) = delete;

  // Starts the loop; returns once the thread has tried its real-time set-up.
  void start();
  void stop();  // asks the loop to end and joins it

  [[nodiscard]] const RealtimeSetup& realtime() const { return rt_; }
  [[nodiscard]] std::uint64_t ticks() const { return ticks_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t overruns() const { return overruns_.load(std::memory_order_relaxed); }
  // Overruns whose tick alone took longer than the period.
  [[nodiscard]] std::uint64_t overruns_from_cost() const { return overruns_cost_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t skipped() const { return skipped_.load(std::memory_order_relaxed); }
  // Most ticks ever run back to back (catching up after a late one).
  [[nodiscard]] std::uint64_t longest_catch_up() const { return longest_burst_.load(std::memory_order_relaxed); }
  // The tick costs and wake-up lateness over the whole run: read after stop().
  [[nodiscard]] const Histogram& tick_cost() const { return cost_; }
  [[nodiscard]] const Histogram& wake_late() const { return late_; }
  // Asks for the current interval's figures; the thread answers at its next
  // tick (interval_ready() turns true) and starts a new interval.
  void request_interval() { interval_requested_.store(true, std::memory_order_release); }
  bool take_interval(IntervalFigures& out);

 private:
  void run();
  void setup_realtime();

  TickTarget& core_;
  PacingConfig config_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> started_{false};
  RealtimeSetup rt_;
  std::atomic<std::uint64_t> ticks_{0}, overruns_{0}, overruns_cost_{0}, skipped_{0}, longest_burst_{0};
  Histogram cost_{1.0, 20000};  // 1 us bins up to 20 ms
  Histogram late_{1.0, 20000};
  Histogram interval_cost_{1.0, 20000};
  std::uint64_t interval_overruns_ = 0;
  std::atomic<bool> interval_requested_{false};
  TripleBuffer<IntervalFigures> interval_;
};

}  // namespace tonus::daemon
