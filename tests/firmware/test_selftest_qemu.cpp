// The Cortex-M4 self-test image booted in QEMU (machine netduinoplus2, an
// STM32F405) with semihosting: its printed result must match the host
// build's run of the same self-test, and the COBS-framed stream it writes on
// USART1 must decode to the host's first reports.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "selftest.hpp"
#include "tonus/firmware/cobs.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus;

namespace {

std::string run(const std::string& cmd, int& status) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) {
    status = -1;
    return out;
  }
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  status = ::pclose(p);
  return out;
}

std::map<std::string, std::string> parse(const std::string& text) {
  std::map<std::string, std::string> kv;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) kv[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return kv;
}

std::vector<long> numbers(const std::string& s) {
  std::vector<long> v;
  std::istringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) v.push_back(std::stol(item));
  return v;
}

template <class Array>
std::string join(const Array& a) {
  std::string s;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (k != 0) s.push_back(',');
    s.append(std::to_string(a[k]));
  }
  return s;
}

}  // namespace

TEST_CASE("self-test on the Cortex-M4 (QEMU) matches the host build") {
  const std::string elf = TONUS_SELFTEST_ELF;
  const std::string qemu = TONUS_QEMU_ARM;
  REQUIRE_MESSAGE(qemu.find("NOTFOUND") == std::string::npos,
                  "qemu-system-arm not found: install it (scripts/install-deps.sh installs qemu-system-arm)");
  REQUIRE_MESSAGE(std::filesystem::exists(elf), "missing " << elf
                                                           << ": build the arm preset first (cmake --preset arm && "
                                                              "cmake --build --preset arm)");
  const std::string usart =
      (std::filesystem::temp_directory_path() / ("tonus-usart-" + std::to_string(::getpid()) + ".bin")).string();
  const std::string cmd = "timeout 60 " + qemu +
                          " -M netduinoplus2 -nographic -monitor none -icount shift=0 -serial file:" + usart +
                          " -semihosting-config enable=on,target=native -kernel " + elf + " 2>&1";
  int status = 0;
  const std::string out = run(cmd, status);
  INFO("qemu output:\n" << out);
  REQUIRE(status == 0);
  REQUIRE(out.find("tonus-selftest end") != std::string::npos);
  const auto arm = parse(out);

  std::vector<proto::StreamMessage> host_reports;
  fw::SelftestResult host;
  fw::run_selftest(
      host,
      [](void* ctx, const proto::StreamMessage& m) {
        auto& v = *static_cast<std::vector<proto::StreamMessage>*>(ctx);
        if (v.size() < 16) v.push_back(m);
      },
      &host_reports);

  // Counts are exact; levels and envelopes within 0.5 % of full scale (the
  // design's libm calls differ between newlib and glibc in the last bits).
  CHECK(std::stol(arm.at("reports")) == host.reports);
  CHECK(std::stol(arm.at("lost_blocks")) == host.lost_blocks);
  CHECK(std::stol(arm.at("flags_seen")) == host.flags_seen);
  const auto close = [](const std::string& what, const std::vector<long>& a, const auto& h, long tol) {
    REQUIRE(a.size() == h.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      INFO(what << "[" << k << "] arm " << a[k] << " host " << h[k]);
      CHECK(std::labs(a[k] - static_cast<long>(h[k])) <= tol);
    }
  };
  close("level_max", numbers(arm.at("level_max")), host.level_max, 330);
  close("level_mid", numbers(arm.at("level_mid")), host.level_at_mid, 330);
  close("level_final", numbers(arm.at("level_final")), host.level_final, 330);
  close("envelope_final", numbers(arm.at("envelope_final")), host.envelope_final, 330);
  CHECK(std::labs(std::stol(arm.at("notch_depth_mdb")) - host.notch_depth_mdb) <= 3000);
  CHECK(std::stol(arm.at("highpass_corner_mdb")) == doctest::Approx(host.highpass_corner_mdb).epsilon(0.001));
  CHECK(std::stol(arm.at("group_delay_us")) == doctest::Approx(host.group_delay_us).epsilon(0.001));
  const bool bit_exact = std::stol(arm.at("stream_crc")) == host.stream_crc;
  // Without FMA contraction (-ffp-contract=off) both builds are IEEE single
  // precision step for step: the whole stream must be bit-identical.
  CHECK(bit_exact);
  MESSAGE("arm levels " << arm.at("level_mid") << " / host " << join(host.level_at_mid)
                        << "; streams bit-exact: " << std::string(bit_exact ? "yes" : "no"));

  // Cost on the Thumb-2 instruction set: with -icount shift=0 every instruction
  // advances virtual time equally, so SysTick ticks / ticks-per-instruction of a
  // known 2,000,000-instruction loop counts instructions (a measurement, not a timing).
  const double ticks_per_instruction = std::stod(arm.at("cost_loop_ticks_per_2M_instructions")) / 2e6;
  REQUIRE(ticks_per_instruction > 0.0);
  const double per_frame =
      std::stod(arm.at("cost_poll_ticks")) / ticks_per_instruction / std::stod(arm.at("cost_frames"));
  MESSAGE("Cortex-M4 (Thumb-2) instructions per 8-channel frame in Device::poll: " << per_frame);
  CHECK(per_frame > 100.0);

  // The self-test result itself must make sense: pairs 0-1 co-contract in the
  // middle, pairs 2-3 only reciprocally at the end; no fault flags.
  CHECK(host.level_at_mid[0] > 10000);
  CHECK(host.level_at_mid[1] > 10000);
  CHECK(host.level_final[2] < host.level_at_mid[0] / 4);
  CHECK(host.flags_seen == 0);
  CHECK(host.notch_depth_mdb < -60000);
  CHECK(host.highpass_corner_mdb == doctest::Approx(-3010).epsilon(0.01));

  // USART1: COBS frames, each one encoded stream message.
  std::ifstream in(usart, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(usart);
  std::vector<proto::StreamMessage> streamed;
  std::vector<std::uint8_t> frame;
  for (std::uint8_t b : bytes) {
    if (b != 0) {
      frame.push_back(b);
      continue;
    }
    std::array<std::uint8_t, proto::kMaxMessageSize> msg{};
    const std::size_t n = fw::cobs::decode(frame, msg);
    frame.clear();
    proto::StreamMessage m{};
    REQUIRE(proto::decode_stream(std::span<const std::uint8_t>(msg).first(n), m) == proto::Error::ok);
    streamed.push_back(m);
  }
  REQUIRE(streamed.size() == host_reports.size());
  for (std::size_t k = 0; k < streamed.size(); ++k) {
    CHECK(streamed[k].sequence == host_reports[k].sequence);
    CHECK(streamed[k].device_time_us == host_reports[k].device_time_us);
    CHECK(streamed[k].status == host_reports[k].status);
    for (std::size_t ch = 0; ch < 8; ++ch) {
      CHECK(std::abs(streamed[k].envelopes[ch] - host_reports[k].envelopes[ch]) <= 330);
    }
  }
}
