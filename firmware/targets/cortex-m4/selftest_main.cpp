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

}  // namespace

extern "C" void firmware_main() {
  f405::usart::init(115200);
  f405::semihosting::write(f405::clocks().on_pll ? "clock: PLL 168 MHz\n" : "clock: HSI 16 MHz (no HSE)\n");
  fw::SelftestResult r;
  std::uint32_t sent = 0;
  fw::run_selftest(r, &stream_report, &sent);
  fw::format_selftest(r, g_text, sizeof g_text);
  f405::semihosting::write(g_text);
  f405::semihosting::exit(r.reports > 0);
}
