// tonus-band-selftest: the same start-up code and core on the real instruction
// set, run under QEMU (machine netduinoplus2, an STM32F405) with semihosting.
// Runs the signal-chain self-test on the built-in synthetic EMG, prints the
// result, streams the first reports COBS-framed on USART1, and exits.
#include <array>

#include "clock.hpp"
#include "selftest.hpp"
#include "semihosting.hpp"
#include "tonus/firmware/cobs.hpp"
#include "tonus/protocol/stream.hpp"
#include "usart.hpp"

namespace {

using namespace tonus;

constexpr std::uint32_t kStreamedReports = 16;

void stream_report(void* ctx, const proto::StreamMessage& m) {
  auto& sent = *static_cast<std::uint32_t*>(ctx);
  if (sent >= kStreamedReports) return;
  std::array<std::uint8_t, proto::kMaxMessageSize> msg{};
  std::size_t n = 0;
  if (proto::encode_stream(m, msg, n) != proto::Error::ok) return;
  std::array<std::uint8_t, fw::cobs::max_encoded_size(proto::kMaxMessageSize) + 1> frame{};
  const std::size_t e = fw::cobs::encode(std::span<const std::uint8_t>(msg).first(n), frame);
  frame[e] = 0;  // delimiter
  f405::usart::write(std::span<const std::uint8_t>(frame).first(e + 1));
  ++sent;
}

char g_text[1024];

// SysTick as a free-running 24-bit down-counter, widened by the caller's
// differences (each poll takes far fewer than 2^24 ticks).
std::uint32_t g_last = 0;
std::uint32_t g_total = 0;
std::uint32_t systick_ticks() {
  const std::uint32_t now = *reinterpret_cast<volatile std::uint32_t*>(0xE000E018) & 0xFFFFFFU;  // NOLINT
  g_total += (g_last - now) & 0xFFFFFFU;
  g_last = now;
  return g_total;
}

// 2,000,000 instructions exactly: 1,000,000 x (subs, bne).
__attribute__((noinline)) void known_loop() {
  std::uint32_t n = 1000000;
  asm volatile(
      "1: subs %0, %0, #1\n\t"
      "bne 1b"
      : "+r"(n)
      :
      : "cc");
}

void start_systick() {
  *reinterpret_cast<volatile std::uint32_t*>(0xE000E014) = 0xFFFFFFU;           // LOAD  NOLINT
  *reinterpret_cast<volatile std::uint32_t*>(0xE000E018) = 0;                   // VAL   NOLINT
  *reinterpret_cast<volatile std::uint32_t*>(0xE000E010) = 0b101;               // processor clock, no IRQ, on  NOLINT
  g_last = *reinterpret_cast<volatile std::uint32_t*>(0xE000E018) & 0xFFFFFFU;  // NOLINT
}

// Writes "key=value\n" with an unsigned value.
void print_field(const char* key, std::uint64_t v) {
  char buf[64];
  std::size_t n = 0;
  for (const char* k = key; *k != '\0' && n < 40; ++k) buf[n++] = *k;
  buf[n++] = '=';
  char digits[21];
  std::size_t d = 0;
  do {
    digits[d++] = static_cast<char>('0' + v % 10U);
    v /= 10U;
  } while (v != 0);
  while (d != 0) buf[n++] = digits[--d];
  buf[n++] = '\n';
  buf[n] = '\0';
  f405::semihosting::write(buf);
}

}  // namespace

extern "C" void firmware_main() {
  f405::usart::init(115200);
  f405::semihosting::write(f405::clocks().on_pll ? "clock: PLL 168 MHz\n" : "clock: HSI 16 MHz (no HSE)\n");
  fw::SelftestResult r;
  std::uint32_t sent = 0;
  start_systick();
  // Cost on the real instruction set: under QEMU -icount shift=0 every
  // instruction takes the same virtual time, so ticks / (ticks per
  // instruction of a known loop) counts Thumb-2 instructions.
  const std::uint32_t t0 = systick_ticks();
  known_loop();
  const std::uint32_t loop_ticks = systick_ticks() - t0;
  fw::run_selftest(r, &stream_report, &sent, &systick_ticks);
  fw::format_selftest(r, g_text, sizeof g_text);
  f405::semihosting::write(g_text);
  print_field("cost_loop_ticks_per_2M_instructions", loop_ticks);
  print_field("cost_poll_ticks", r.poll_ticks);
  print_field("cost_frames", r.frames);
  f405::semihosting::exit(r.reports > 0);
}
