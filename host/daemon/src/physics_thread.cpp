#include "tonus/host/daemon/physics_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

namespace tonus::daemon {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * kNsPerS + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t_ns) {
  const timespec ts{static_cast<time_t>(t_ns / kNsPerS), static_cast<long>(t_ns % kNsPerS)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

}  // namespace

PhysicsThread::PhysicsThread(TickTarget& core, const PacingConfig& config) : core_(core), config_(config) {}

PhysicsThread::~PhysicsThread() { stop(); }

void PhysicsThread::setup_realtime() {
  if (config_.realtime_priority > 0) {
    sched_param p{};
    p.sched_priority = config_.realtime_priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    rt_.priority_set = rc == 0;
    if (rc != 0) rt_.priority_error = fmt::format("SCHED_FIFO {}: {}", config_.realtime_priority, std::strerror(rc));
  }
  if (config_.lock_memory) {
    if (kAddressSanitizer) {
      rt_.lock_error = "not under AddressSanitizer (its shadow memory is too large to lock)";
    } else if (mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) == 0) {
      rt_.memory_locked = true;
    } else {
      rt_.lock_error = fmt::format("mlockall: {}", std::strerror(errno));
    }
  }
}

void PhysicsThread::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  started_.store(false);
  thread_ = std::thread([this] { run(); });
  while (!started_.load(std::memory_order_acquire)) std::this_thread::yield();
}

void PhysicsThread::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

bool PhysicsThread::take_interval(IntervalFigures& out) {
  if (!interval_.update()) return false;
  out = interval_.read_slot();
  return true;
}

void PhysicsThread::run() {
  setup_realtime();
  started_.store(true, std::memory_order_release);
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / config_.rate_hz));
  std::int64_t next = now_ns() + period_ns;
  std::uint64_t burst = 0;  // ticks run without sleeping (their deadline had passed)
  while (!stop_.load(std::memory_order_acquire)) {
    sleep_until_ns(next);
    const std::int64_t start = now_ns();
    late_.add(static_cast<double>(start - next) * 1e-3);
    if (start - next < period_ns) {
      burst = 0;
    } else if (burst >= static_cast<std::uint64_t>(config_.max_catch_up_ticks)) {
      // Already max_catch_up_ticks late ticks back to back and the scheduler
      // has kept us behind: skip the missed deadlines here too, so the bound
      // holds however the wake-ups fall, not only after a long tick.
      const std::int64_t behind = (start - next) / period_ns;
      skipped_.fetch_add(static_cast<std::uint64_t>(behind), std::memory_order_relaxed);
      next += behind * period_ns;
      burst = 0;
    } else {
      ++burst;
    }
    if (burst > longest_burst_.load(std::memory_order_relaxed)) longest_burst_.store(burst, std::memory_order_relaxed);
    core_.tick(next / 1000);
    const std::int64_t end = now_ns();
    const double cost_us = static_cast<double>(end - start) * 1e-3;
    cost_.add(cost_us);
    interval_cost_.add(cost_us);
    ticks_.fetch_add(1, std::memory_order_relaxed);
    next += period_ns;
    if (end > next) {
      overruns_.fetch_add(1, std::memory_order_relaxed);
      if (end - start > period_ns) overruns_cost_.fetch_add(1, std::memory_order_relaxed);
      ++interval_overruns_;
      const std::int64_t behind = (end - next) / period_ns;  // whole periods already missed
      if (behind >= config_.max_catch_up_ticks) {
        skipped_.fetch_add(static_cast<std::uint64_t>(behind), std::memory_order_relaxed);
        next += behind * period_ns;
      }
    }
    if (interval_requested_.exchange(false, std::memory_order_acq_rel)) {
      IntervalFigures& f = interval_.write_slot();
      f.ticks = interval_cost_.count();
      f.p50_us = interval_cost_.quantile_us(0.5);
      f.p99_us = interval_cost_.quantile_us(0.99);
      f.max_us = interval_cost_.max_us();
      f.overruns = interval_overruns_;
      core_.close_interval(f.band_latency_p50_us, f.band_latency_p99_us);
      interval_.publish();
      interval_cost_.clear();
      interval_overruns_ = 0;
    }
  }
}

}  // namespace tonus::daemon
