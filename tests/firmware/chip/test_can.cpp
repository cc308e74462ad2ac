// bxCAN on fake registers: the bit timing follows the clock that actually
// runs (checked with RM0090's bit-rate formula), the band stays off the bus on
// the internal oscillator, and a bus missing at boot is retried.
#include <doctest/doctest.h>

#include <cstdint>

#include "board_hal.hpp"
#include "clock.hpp"
#include "fake_registers.hpp"
#include "registers.hpp"

using namespace tonus;
using namespace tonus::f405;

namespace {

// RM0090 32.7.7: bit time = (1 + (TS1 + 1) + (TS2 + 1)) * (BRP + 1) / PCLK1.
double bitrate_of(std::uint32_t btr, std::uint32_t pclk_hz) {
  const std::uint32_t brp = (btr & 0x3FFU) + 1, ts1 = ((btr >> 16U) & 0xFU) + 1, ts2 = ((btr >> 20U) & 7U) + 1;
  return static_cast<double>(pclk_hz) / static_cast<double>(brp * (1 + ts1 + ts2));
}
double sample_point(std::uint32_t btr) {
  const std::uint32_t ts1 = ((btr >> 16U) & 0xFU) + 1, ts2 = ((btr >> 20U) & 7U) + 1;
  return static_cast<double>(1 + ts1) / static_cast<double>(1 + ts1 + ts2);
}

// RCC that brings up the crystal and the PLL (or not), and a bxCAN whose
// INAK follows INRQ when a bus is present.
void model_rcc(bool crystal) {
  auto& f = fake::registers();
  f.on_read[rcc::cr.address] = [crystal](std::uint32_t v) {
    std::uint32_t r = v;
    if (crystal && (v & (1U << 16U)) != 0) r |= 1U << 17U;  // HSERDY
    if (crystal && (v & (1U << 24U)) != 0) r |= 1U << 25U;  // PLLRDY
    return r;
  };
  f.on_read[rcc::cfgr.address] = [](std::uint32_t v) { return v | ((v & 3U) << 2U); };  // SWS = SW
}
bool g_bus = true;  // a bus (and transceiver) is attached

void model_can(bool bus) {
  g_bus = bus;
  auto& f = fake::registers();
  f.on_read[can1::msr.address] = [](std::uint32_t) {
    const bool inrq = (fake::registers().get(can1::mcr.address) & 1U) != 0;
    return inrq || !g_bus ? 1U : 0U;  // without a bus the controller never leaves init
  };
  f.value[can1::tsr.address] = 7U << 26U;  // three empty mailboxes
}
void model_time() {
  fake::registers().value[systick::load.address] = 168000 - 1;
  set_tick_count(0);
}

}  // namespace

TEST_CASE("bit timing: exact 1 Mbit/s (and slower rates) from the clocks the band can run on") {
  for (const std::uint32_t pclk : {42000000U, 16000000U, 8000000U, 36000000U, 48000000U}) {
    for (const std::uint32_t rate : {1000000U, 500000U, 250000U, 125000U}) {
      std::uint32_t btr = 0;
      // (No INFO here: doctest's scope objects need RTTI, which this target is built without.)
      REQUIRE(can_bit_timing(pclk, rate, btr));
      CHECK(bitrate_of(btr, pclk) == doctest::Approx(rate).epsilon(1e-12));
      CHECK(sample_point(btr) >= 0.75);
      CHECK(sample_point(btr) <= 0.90);
      CHECK((btr & ~((7U << 20U) | (0xFU << 16U) | 0x3FFU)) == 0);  // no mode bits, SJW 1
    }
  }
  std::uint32_t btr = 0;
  REQUIRE(can_bit_timing(42000000U, 1000000U, btr));
  CHECK(btr == ((1U << 20U) | (10U << 16U) | 2U));  // 14 quanta, sample point 85.7 %
  CHECK_FALSE(can_bit_timing(42000000U, 1000001U, btr));
  CHECK_FALSE(can_bit_timing(1000000U, 1000000U, btr));  // fewer than 8 quanta per bit
  CHECK_FALSE(can_bit_timing(42000000U, 0U, btr));
}

TEST_CASE("with the crystal the bus runs at exactly 1 Mbit/s, without it the band stays off the bus") {
  SUBCASE("crystal and PLL") {
    fake::reset();
    model_rcc(true);
    model_can(true);
    model_time();
    clock_init();
    REQUIRE(clocks().on_pll);
    BxCan can;
    REQUIRE(can.init(1));
    CHECK(bitrate_of(fake::registers().get(can1::btr.address), clocks().apb1_hz) == doctest::Approx(1e6));
    CHECK(can.fault() == CanFault::none);
  }
  SUBCASE("the crystal failed: HSI") {
    // The old driver kept the 42 MHz timing on the 16 MHz oscillator: 381 kbit/s on a 1 Mbit/s bus.
    fake::reset();
    model_rcc(false);
    model_can(true);
    model_time();
    clock_init();
    REQUIRE_FALSE(clocks().on_pll);
    BxCan can;
    CHECK_FALSE(can.init(1));
    CHECK(can.fault() == CanFault::no_crystal);
    // Never left init mode with a wrong timing: INRQ never cleared, BTR never set.
    for (const std::uint32_t mcr : fake::registers().written(can1::mcr.address)) CHECK((mcr & 1U) == 1U);
    const auto btr = fake::registers().written(can1::btr.address);
    for (const std::uint32_t b : btr) CHECK(bitrate_of(b, clocks().apb1_hz) == doctest::Approx(1e6));
    proto::CanFrame f{};
    CHECK_FALSE(can.send(f));
    CHECK(can.idle());
  }
}

TEST_CASE("a bus missing at boot is retried every second, and the band joins it when it appears") {
  fake::reset();
  model_rcc(true);
  model_can(false);
  model_time();
  clock_init();
  BxCan can;
  CHECK_FALSE(can.init(1));
  CHECK(can.fault() == CanFault::no_bus);
  proto::CanFrame f{};
  f.id = 0x181;
  f.dlc = 1;
  CHECK_FALSE(can.send(f));  // within the second: not retried
  CHECK(can.init_retries() == 1);
  g_bus = true;  // plugged in
  set_tick_count(1100);
  CHECK(can.send(f));  // retried, joined, sent
  CHECK(can.up());
  CHECK(can.fault() == CanFault::none);
  CHECK((fake::registers().get(can1::tir(0).address) >> 21U) == 0x181U);
}
