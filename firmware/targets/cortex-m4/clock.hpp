// Clock tree of the band and its monotonic microsecond clock (SysTick).
//   HSE 8 MHz crystal -> PLL (M 8, N 336, P 2, Q 7): SYSCLK 168 MHz, USB 48 MHz
//   AHB 168 MHz, APB1 42 MHz (timers 84 MHz, bxCAN 42 MHz), APB2 84 MHz
//   flash: 5 wait states, prefetch, instruction and data caches (ART)
// Every wait on a ready flag is bounded: without a crystal (or under QEMU,
// which does not model the RCC) the band stays on the 16 MHz HSI and says so.
#pragma once

#include <cstdint>

namespace tonus::f405 {

inline constexpr std::uint32_t kHseHz = 8000000;
inline constexpr std::uint32_t kSysclkHz = 168000000;
inline constexpr std::uint32_t kHsiHz = 16000000;

struct ClockState {
  std::uint32_t sysclk_hz = kHsiHz;
  std::uint32_t apb1_hz = kHsiHz;
  std::uint32_t apb1_timer_hz = kHsiHz;
  std::uint32_t apb2_hz = kHsiHz;
  bool on_pll = false;
};

void clock_init();
const ClockState& clocks();

// SysTick at 1 kHz, extended to a 64-bit microsecond count. micros() is safe
// from any context (main loop or interrupt): it only reads.
void systick_start();
std::uint64_t micros();
void systick_tick();                    // the SysTick interrupt's work
void set_tick_count(std::uint64_t ms);  // start-up (and tests): the millisecond count

}  // namespace tonus::f405
