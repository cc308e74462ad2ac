// The machine's floor for a 1 kHz real-time loop: an empty loop sleeping to
// absolute 1 ms deadlines (clock_nanosleep TIMER_ABSTIME, SCHED_FIFO 20 when
// permitted), as tonusd's physics thread does, with no work at all. The share
// of wake-ups later than `--over-us` is the overrun share no daemon can beat
// on this machine (BENCHMARKS.md compares tonusd against it).
//
// --busy measures what is left when the thread never sleeps: a SCHED_FIFO spin
// reading the clock, counting each 1 ms slot that holds a gap over `--over-us`
// (the core taken away: an interrupt storm, or a virtual machine's host
// descheduling the vCPU). It spins 900 ms of every second, so the kernel's
// real-time throttling (950 ms per second) never cuts in. Where the sleeping
// loop is much worse than the spinning one, the lateness is in waking a halted
// core, not in losing it.
//   tonus-bench-wakeup [--seconds N] [--over-us U] [--busy]
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <vector>

namespace {

long long now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1'000'000'000LL + t.tv_nsec;
}

int spin(double seconds, double over_us, bool rt) {
  const auto over_ns = static_cast<long long>(over_us * 1e3);
  long long slots = 0, slots_hit = 0, max_gap = 0, hit_slot = -1;
  const auto whole_seconds = static_cast<long long>(std::max(1.0, seconds));
  for (long long s = 0; s < whole_seconds; ++s) {
    const long long start = now_ns();
    long long prev = start;
    for (long long t = start; t - start < 900'000'000; t = now_ns()) {
      const long long gap = t - prev;
      max_gap = std::max(max_gap, gap);
      const long long slot = (t - start) / 1'000'000;
      if (gap > over_ns && slot != hit_slot) {
        ++slots_hit;
        hit_slot = slot;
      }
      prev = t;
    }
    slots += 900;
    const timespec rest{0, 100'000'000};
    nanosleep(&rest, nullptr);
  }
  std::printf("busy spin, %lld ms slots (SCHED_FIFO %s): slots with a gap over %.0f us: %.3f %%, longest gap %.0f us\n",
              slots, rt ? "yes" : "no", over_us, 100.0 * static_cast<double>(slots_hit) / static_cast<double>(slots),
              static_cast<double>(max_gap) * 1e-3);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  double over_us = 900.0;  // a tonusd tick costs ~50-100 us: a wake-up this late makes it overrun
  bool busy = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--busy") == 0) busy = true;
    if (i + 1 >= argc) continue;
    if (std::strcmp(argv[i], "--seconds") == 0) seconds = std::atof(argv[i + 1]);
    if (std::strcmp(argv[i], "--over-us") == 0) over_us = std::atof(argv[i + 1]);
  }
  sched_param p{};
  p.sched_priority = 20;
  const bool rt = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  if (busy) return spin(seconds, over_us, rt);
  const auto n = static_cast<std::size_t>(std::max(1.0, seconds * 1000.0));
  std::vector<double> late(n);
  long long next = now_ns();
  for (std::size_t i = 0; i < n; ++i) {
    next += 1'000'000;
    const timespec ts{static_cast<time_t>(next / 1'000'000'000), static_cast<long>(next % 1'000'000'000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
    }
    late[i] = static_cast<double>(now_ns() - next) * 1e-3;
  }
  std::vector<double> sorted = late;
  std::sort(sorted.begin(), sorted.end());
  const auto q = [&](double f) {
    return sorted[std::min(n - 1, static_cast<std::size_t>(f * static_cast<double>(n)))];
  };
  const auto over = static_cast<double>(std::count_if(late.begin(), late.end(), [&](double l) { return l > over_us; }));
  std::printf(
      "empty 1 kHz loop, %zu wake-ups (SCHED_FIFO %s): late p50 %.0f us, p99 %.0f us, p99.9 %.0f us, max %.0f us; "
      "later than %.0f us: %.3f %%\n",
      n, rt ? "yes" : "no", q(0.5), q(0.99), q(0.999), sorted.back(), over_us, 100.0 * over / static_cast<double>(n));
  return 0;
}
