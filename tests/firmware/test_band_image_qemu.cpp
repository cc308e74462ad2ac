// The band's real image (tonus-band-f405.elf) booted in QEMU (netduinoplus2,
// an STM32F405): it must boot past the unique-id read that used to HardFault,
// report on its console (USART1) what it found, and keep its main loop going.
// QEMU models neither the crystal, the OTG core, bxCAN nor the ADC's DMA, so
// the expected state is: internal oscillator, no serial, CAN off, sampler
// stalled (the fault path), a status line every second.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>
#include "support/read_file.hpp"

using tonus::test::read_file;

namespace {}  // namespace

TEST_CASE("the band image boots in QEMU and runs its main loop") {
  const std::string elf = TONUS_BAND_ELF;
  const std::string qemu = TONUS_QEMU_ARM;
  REQUIRE_MESSAGE(qemu.find("NOTFOUND") == std::string::npos, "qemu-system-arm not found");
  REQUIRE_MESSAGE(std::filesystem::exists(elf), "missing " << elf << ": build the arm preset first");
  const std::string console =
      (std::filesystem::temp_directory_path() / ("tonus-band-console-" + std::to_string(::getpid()) + ".txt")).string();
  // The image never exits: QEMU is stopped after 4 s of wall time.
  const std::string cmd = "timeout 4 " + qemu +
                          " -M netduinoplus2 -nographic -monitor none -icount shift=0 -serial file:" + console +
                          " -kernel " + elf + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string out = read_file(console);
  std::filesystem::remove(console);
  INFO("console:\n" << out);
  CHECK(WEXITSTATUS(status) == 124);  // still running when stopped: no lockup, no exit

  const std::regex boot(
      R"(tonus-band \d+\.\d+\.\d+ boot clock=(\S+) serial=(\S+) watchdog_reset=0 storage=\S+ usb=(\S+) can=(\S+))");
  std::smatch m;
  REQUIRE(std::regex_search(out, m, boot));
  CHECK(m[1] == "hsi-16mhz");       // QEMU has no crystal: the clock stays on the HSI
  CHECK(m[2] == "none");            // the unique id is not there, and reading it no longer faults
  CHECK(m[3] == "off");             // no OTG core
  CHECK(m[4] == "off-no-crystal");  // CAN refuses an inexact clock

  const std::regex status_line(R"(status t_ms=(\d+) reports=(\d+) lost_blocks=\d+ tx_dropped=\d+ sampler=(\w+))");
  std::vector<long> times;
  std::vector<std::string> sampler;
  for (auto it = std::sregex_iterator(out.begin(), out.end(), status_line); it != std::sregex_iterator(); ++it) {
    times.push_back(std::stol((*it)[1]));
    sampler.push_back((*it)[3]);
  }
  REQUIRE(times.size() >= 2);
  // Line k is due at (k + 1) s of the band's clock and printed on the first
  // main-loop pass after it (every pass ends in WFI, woken at least each 1 ms tick).
  for (std::size_t k = 0; k < times.size(); ++k) {
    const long due = 1000L * static_cast<long>(k + 1);
    CHECK(times[k] >= due);
    CHECK(times[k] <= due + 5);
  }
  CHECK(sampler.back() == "stalled");  // no samples: detected, reported
}
