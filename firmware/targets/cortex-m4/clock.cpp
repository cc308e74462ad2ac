#include "clock.hpp"

#include <atomic>

#include "registers.hpp"

namespace tonus::f405 {

namespace {

ClockState g_clocks;

// The millisecond count, extended to 64 bits by its only writer, the SysTick
// interrupt, under a sequence counter (odd while it writes). micros() only
// reads, so any context may call it: the main loop and the DMA interrupt do.
std::atomic<std::uint32_t> g_tick_seq{0};
std::atomic<std::uint32_t> g_ms_low{0};
std::atomic<std::uint32_t> g_ms_high{0};

bool wait_set(Reg r, std::uint32_t bits, std::uint32_t spins) {
  while (spins-- != 0) {
    if ((r.read() & bits) == bits) return true;
  }
  return false;
}

}  // namespace

void clock_init() {
  constexpr std::uint32_t kHseOn = 1U << 16U, kHseRdy = 1U << 17U, kPllOn = 1U << 24U, kPllRdy = 1U << 25U;
  g_clocks = ClockState{};  // the internal oscillator until the PLL runs
  rcc::cr.set(kHseOn);
  if (!wait_set(rcc::cr, kHseRdy, 200000)) return;  // no crystal: stay on HSI
  // PLL: M = 8, N = 336, P = 2 (00), Q = 7, source HSE.
  rcc::pllcfgr.write(8U | (336U << 6U) | (0U << 16U) | (1U << 22U) | (7U << 24U));
  rcc::cr.set(kPllOn);
  if (!wait_set(rcc::cr, kPllRdy, 200000)) return;
  // 5 wait states at 168 MHz / 3.3 V, prefetch + I/D caches.
  flash::acr.write(5U | (1U << 8U) | (1U << 9U) | (1U << 10U));
  // AHB /1, APB1 /4 (101), APB2 /2 (100), SYSCLK from PLL (10).
  rcc::cfgr.write((5U << 10U) | (4U << 13U) | 2U);
  if (!wait_set(rcc::cfgr, 2U << 2U, 200000)) return;  // SWS == PLL
  g_clocks.sysclk_hz = kSysclkHz;
  g_clocks.apb1_hz = kSysclkHz / 4;
  g_clocks.apb1_timer_hz = kSysclkHz / 2;
  g_clocks.apb2_hz = kSysclkHz / 2;
  g_clocks.on_pll = true;
}

const ClockState& clocks() { return g_clocks; }

void systick_start() {
  systick::load.write(g_clocks.sysclk_hz / 1000U - 1U);
  systick::val.write(0);
  systick::ctrl.write(0b111);  // processor clock, interrupt, enable
}

std::uint64_t micros() {
  constexpr std::uint32_t kPendStSet = 1U << 26U;  // ICSR: SysTick interrupt pending
  std::uint32_t seq = 0, low = 0, high = 0, val = 0, icsr = 0;
  do {
    seq = g_tick_seq.load(std::memory_order_acquire);
    low = g_ms_low.load(std::memory_order_relaxed);
    high = g_ms_high.load(std::memory_order_relaxed);
    val = systick::val.read();
    icsr = scb::icsr.read();
    std::atomic_thread_fence(std::memory_order_acquire);
  } while ((seq & 1U) != 0 || seq != g_tick_seq.load(std::memory_order_relaxed));
  const std::uint32_t load = systick::load.read() + 1U;
  std::uint64_t ms = (static_cast<std::uint64_t>(high) << 32U) | low;
  // The counter wrapped but its interrupt has not run yet (we are in a
  // handler of equal or higher priority, or interrupts are masked): count it.
  // A large VAL means the wrap happened before our read of it.
  if ((icsr & kPendStSet) != 0 && val > load / 2U) ++ms;
  return ms * 1000U + static_cast<std::uint64_t>(load - 1U - val) * 1000U / load;
}

void set_tick_count(std::uint64_t ms) {
  // One writer (the SysTick interrupt, or start-up before it runs): the
  // sequence counter is odd while the two words change, so readers retry.
  g_tick_seq.store(g_tick_seq.load(std::memory_order_relaxed) + 1U, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  g_ms_low.store(static_cast<std::uint32_t>(ms), std::memory_order_relaxed);
  g_ms_high.store(static_cast<std::uint32_t>(ms >> 32U), std::memory_order_relaxed);
  g_tick_seq.store(g_tick_seq.load(std::memory_order_relaxed) + 1U, std::memory_order_release);
}

void systick_tick() {
  const std::uint64_t ms = (static_cast<std::uint64_t>(g_ms_high.load(std::memory_order_relaxed)) << 32U) |
                           g_ms_low.load(std::memory_order_relaxed);
  set_tick_count(ms + 1U);
}

}  // namespace tonus::f405

extern "C" void SysTick_Handler() { tonus::f405::systick_tick(); }
