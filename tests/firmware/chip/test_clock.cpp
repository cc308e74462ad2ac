// The band's microsecond clock on fake registers: safe from any context (the
// DMA interrupt reads it while the main loop does), across the 2^32 ms wrap,
// and with a SysTick interrupt still pending.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "clock.hpp"
#include "fake_registers.hpp"
#include "registers.hpp"

using namespace tonus::f405;

namespace {

constexpr std::uint32_t kLoad = 168000 - 1;  // 1 ms at 168 MHz

// Reads micros() until `stop`. False if it ever went backwards or jumped by
// 2^31 ms or more (the old clock's failure added 2^32 ms).
bool monotonic_reader(const std::atomic<bool>& stop, std::atomic<std::uint64_t>& reads) {
  std::uint64_t last = micros();
  bool ok = true;
  while (!stop.load(std::memory_order_relaxed)) {
    const std::uint64_t now = micros();
    if (now < last || now - last >= (std::uint64_t{1} << 31U) * 1000U) ok = false;
    last = now;
    reads.fetch_add(1, std::memory_order_relaxed);
  }
  return ok;
}

}  // namespace

TEST_CASE("micros() read by the main loop and an interrupt at once never jumps") {
  // Three threads stand for the SysTick interrupt, the main loop and the DMA
  // interrupt. The old clock kept its 64-bit extension in state that every
  // reader wrote: a reader that saw an older count than another one added 2^32 ms.
  fake::reset();
  fake::registers().value[systick::load.address] = kLoad;
  fake::registers().value[systick::val.address] = kLoad / 3;
  set_tick_count(0);
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> reads_main{0}, reads_irq{0};
  bool main_ok = true, irq_ok = true;
  std::thread main_loop([&] { main_ok = monotonic_reader(stop, reads_main); });
  std::thread dma_irq([&] { irq_ok = monotonic_reader(stop, reads_irq); });
  // Tick while both readers read, interleaved with them.
  std::uint32_t ticks = 0;
  while (ticks < 300000U || reads_main.load() < 100000U || reads_irq.load() < 100000U) {
    systick_tick();
    ++ticks;
    if (ticks % 1024U == 0) std::this_thread::yield();
  }
  stop.store(true);
  main_loop.join();
  dma_irq.join();
  MESSAGE(reads_main.load() << " + " << reads_irq.load() << " concurrent reads over " << ticks << " ticks");
  CHECK(main_ok);
  CHECK(irq_ok);
  CHECK(reads_main.load() >= 100000U);
  CHECK(reads_irq.load() >= 100000U);
  const std::uint64_t end = micros();
  CHECK(end / 1000U == ticks);
}

TEST_CASE("micros() counts on across 2^32 milliseconds") {
  fake::reset();
  fake::registers().value[systick::load.address] = kLoad;
  fake::registers().value[systick::val.address] = kLoad;  // just reloaded: 0 us into the ms
  const std::uint64_t start_ms = (std::uint64_t{1} << 32U) - 3;
  set_tick_count(start_ms);
  std::uint64_t last = micros();
  CHECK(last == start_ms * 1000U);
  for (int k = 0; k < 6; ++k) {
    systick_tick();
    const std::uint64_t now = micros();
    CHECK(now == last + 1000U);
    last = now;
  }
  CHECK(last == (start_ms + 6) * 1000U);
}

TEST_CASE("a SysTick wrap whose interrupt has not run yet is counted") {
  fake::reset();
  fake::registers().value[systick::load.address] = kLoad;
  set_tick_count(100);
  fake::registers().value[systick::val.address] = kLoad - 10;  // reloaded 10 cycles ago
  fake::registers().value[scb::icsr.address] = 1U << 26U;      // PENDSTSET: its interrupt waits
  CHECK(micros() == 101000U);
  fake::registers().value[scb::icsr.address] = 0;
  CHECK(micros() == 100000U);  // the same counter with the interrupt already run: 100 ms + 0 us
  // Late in the millisecond a pending flag is the next wrap's, not yet reflected in VAL.
  fake::registers().value[systick::val.address] = 5;
  fake::registers().value[scb::icsr.address] = 1U << 26U;
  CHECK(micros() == 100999U);
}

TEST_CASE("a reader whose sample is older than another reader's gets its own time, not 2^32 ms more") {
  // The main loop samples the count (N), the SysTick and DMA interrupts run
  // (N + 1, and the DMA handler reads the clock), then the main loop finishes
  // its reading with its sample N. The old clock kept the last count seen in
  // state shared by all readers and took N < N + 1 for a 32-bit wrap. Setting
  // the count back to N stands for the main loop's older sample.
  fake::reset();
  fake::registers().value[systick::load.address] = kLoad;
  fake::registers().value[systick::val.address] = kLoad;
  set_tick_count(5001);
  CHECK(micros() == 5001000U);  // the interrupt's reading
  set_tick_count(5000);
  CHECK(micros() == 5000000U);  // the preempted main loop's
}
