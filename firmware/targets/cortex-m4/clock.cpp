#include "clock.hpp"

#include "registers.hpp"

namespace tonus::f405 {

namespace {

ClockState g_clocks;
volatile std::uint32_t g_ms = 0;  // 32 bits: one atomic load on the M4
std::uint32_t g_last_ms = 0;      // main-loop side extension to 64 bits
std::uint64_t g_high = 0;

bool wait_set(Reg r, std::uint32_t bits, std::uint32_t spins) {
  while (spins-- != 0) {
    if ((r.read() & bits) == bits) return true;
  }
  return false;
}

}  // namespace

void clock_init() {
  constexpr std::uint32_t kHseOn = 1U << 16U, kHseRdy = 1U << 17U, kPllOn = 1U << 24U, kPllRdy = 1U << 25U;
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
  // Read the count on both sides of the down-counter to catch a wrap in between.
  // Called from the main loop only, so the 64-bit extension needs no lock.
  std::uint32_t ms = 0;
  std::uint32_t val = 0;
  do {
    ms = g_ms;
    val = systick::val.read();
  } while (ms != g_ms);
  if (ms < g_last_ms) g_high += 1ULL << 32U;  // the 32-bit count wrapped (every 49.7 days)
  g_last_ms = ms;
  const std::uint32_t load = systick::load.read() + 1U;
  return (g_high + ms) * 1000U + static_cast<std::uint64_t>(load - 1U - val) * 1000U / load;
}

}  // namespace tonus::f405

extern "C" void SysTick_Handler() { tonus::f405::g_ms = tonus::f405::g_ms + 1U; }
