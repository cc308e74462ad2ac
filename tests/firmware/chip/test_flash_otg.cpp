// Flash storage and the USB controller driver on fake registers: the two
// configuration sectors, the ART cache flush after erase and program, and
// suspend/resume and endpoint halt on the OTG core.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "board_hal.hpp"
#include "clock.hpp"
#include "fake_registers.hpp"
#include "firmware/usb_setup.hpp"
#include "otg_fs_dcd.hpp"
#include "registers.hpp"
#include "tonus/firmware/nv_record.hpp"
#include "tonus/usb/device_core.hpp"

using namespace tonus;
using namespace tonus::f405;
using tonus::test::setup_packet;

namespace {

constexpr std::uint32_t kIcEn = 1U << 9U, kDcEn = 1U << 10U, kIcRst = 1U << 11U, kDcRst = 1U << 12U;

// RM0090 3.5.2: "the data cache can be flushed only when it is disabled". A
// flush = DCRST written while DCEN is clear (likewise for the instruction
// cache), and both enabled again afterwards.
bool caches_flushed_after(std::size_t first_write) {
  const auto& w = fake::registers().writes;
  bool d = false, i = false;
  for (std::size_t k = first_write; k < w.size(); ++k) {
    if (w[k].first != flash::acr.address) continue;
    if ((w[k].second & kDcRst) != 0 && (w[k].second & kDcEn) == 0) d = true;
    if ((w[k].second & kIcRst) != 0 && (w[k].second & kIcEn) == 0) i = true;
  }
  const std::uint32_t acr = fake::registers().get(flash::acr.address);
  return d && i && (acr & (kIcEn | kDcEn)) == (kIcEn | kDcEn) && (acr & (kIcRst | kDcRst)) == 0;
}

}  // namespace

TEST_CASE("flash storage: two sectors (1 and 2), caches flushed after every erase and program") {
  fake::reset();
  fake::registers().value[flash::acr.address] = 5U | (1U << 8U) | kIcEn | kDcEn;
  fake::registers().on_write[flash::sr.address] = [](std::uint32_t old, std::uint32_t w) { return old & ~w; };
  FlashStorage storage;
  REQUIRE(storage.sector_count() == 2);
  REQUIRE(storage.size() == fake::nvm().size());

  std::size_t mark = fake::registers().writes.size();
  REQUIRE(storage.erase(1));
  const auto cr = fake::registers().written(flash::cr.address);
  bool sector2 = false;
  for (const std::uint32_t v : cr) sector2 = sector2 || ((v & 2U) != 0 && ((v >> 3U) & 0xFU) == 2U);
  CHECK(sector2);  // SER with SNB 2: the second configuration sector
  CHECK(caches_flushed_after(mark));
  CHECK_FALSE(storage.erase(2));

  mark = fake::registers().writes.size();
  const std::vector<std::uint8_t> data{1, 2, 0xFF, 4};
  REQUIRE(storage.program(16384 + 8, data));
  CHECK(fake::nvm()[16384 + 8] == 1);
  CHECK(fake::nvm()[16384 + 11] == 4);
  CHECK(caches_flushed_after(mark));
  CHECK_FALSE(storage.program(storage.size() - 2, data));  // past the end

  // The record log runs on it: a save lands and reads back.
  fw::Persisted p{};
  p.config.envelope_tau_ms = 77;
  REQUIRE(fw::save_persisted(storage, p));
  fw::Persisted out{};
  REQUIRE(fw::load_persisted(storage, out) == fw::LoadResult::loaded);
  CHECK(out == p);
}

namespace {

// The OTG core's registers as far as init, suspend/resume and halt need them.
void model_otg() {
  auto& f = fake::registers();
  f.on_read[otg::grstctl.address] = [](std::uint32_t v) { return v | (1U << 31U); };   // AHB idle
  f.on_write[otg::grstctl.address] = [](std::uint32_t, std::uint32_t) { return 0U; };  // resets/flushes finish at once
  f.on_write[otg::gintsts.address] = [](std::uint32_t old, std::uint32_t w) { return old & ~w; };  // write 1 to clear
  f.value[systick::load.address] = 168000 - 1;
  // Every clock reading lets a millisecond pass (the 25 ms wait in init). The
  // hook sits on LOAD, which micros() reads after its consistent snapshot.
  f.on_read[systick::load.address] = [](std::uint32_t v) {
    systick_tick();
    return v;
  };
}

// The OTG controller brought up on the modelled registers, with the device
// core attached, reset and configured (SET_CONFIGURATION 1) by the host.
struct ConfiguredOtg {
  ConfiguredOtg() {
    fake::reset();
    model_otg();
    set_tick_count(0);
    dcd.attach(&core);
    init_ok = dcd.init();
    core.on_bus_reset();
    core.on_setup(setup_packet(0x00, 9, 1, 0));
  }
  OtgFsDcd dcd;
  usb::DeviceCore core{dcd, 1};
  bool init_ok = false;
};

}  // namespace

TEST_CASE("OTG: resume after suspend is handled, and the band streams again without re-enumeration") {
  ConfiguredOtg otg_fs;
  OtgFsDcd& dcd = otg_fs.dcd;
  usb::DeviceCore& core = otg_fs.core;
  REQUIRE(otg_fs.init_ok);
  CHECK((fake::registers().get(otg::gintmsk.address) & (1U << 31U)) != 0);  // WKUPINT enabled
  REQUIRE(core.connected());

  fake::registers().value[otg::gintsts.address] = 1U << 11U;  // USBSUSP
  dcd.on_irq();
  CHECK_FALSE(core.connected());
  fake::registers().value[otg::pcgcctl.address] = 1U;         // the PHY clock was stopped in suspend
  fake::registers().value[otg::gintsts.address] = 1U << 31U;  // WKUPINT: the host resumes
  dcd.on_irq();
  CHECK(core.connected());  // before: silent until a bus reset
  CHECK((fake::registers().get(otg::pcgcctl.address) & 3U) == 0);
  CHECK(core.resumes() == 1);

  proto::hid::Report r{};
  r[0] = proto::hid::kReportIdStream;
  CHECK(core.send_input(r));
  CHECK(dcd.hid_busy());
}

TEST_CASE("OTG: ENDPOINT_HALT stalls EP1 IN and drops its FIFO, clearing it resets the data toggle") {
  ConfiguredOtg otg_fs;
  OtgFsDcd& dcd = otg_fs.dcd;
  usb::DeviceCore& core = otg_fs.core;
  REQUIRE(otg_fs.init_ok);
  proto::hid::Report r{};
  r[0] = proto::hid::kReportIdStream;
  REQUIRE(core.send_input(r));
  REQUIRE(dcd.hid_busy());
  constexpr std::uint32_t kStall = 1U << 21U, kSd0Pid = 1U << 28U;
  core.on_setup(setup_packet(0x02, 3, 0, 0x81));  // SET_FEATURE(ENDPOINT_HALT, EP1 IN)
  CHECK((fake::registers().get(otg::diepctl(1).address) & kStall) != 0);
  CHECK_FALSE(dcd.hid_busy());  // the FIFO was flushed
  CHECK(core.send_input(r));    // queued, but the halted endpoint is not loaded
  CHECK_FALSE(dcd.hid_busy());
  core.on_setup(setup_packet(0x02, 1, 0, 0x81));  // CLEAR_FEATURE
  const std::uint32_t ctl = fake::registers().get(otg::diepctl(1).address);
  CHECK((ctl & kStall) == 0);
  CHECK((ctl & kSd0Pid) != 0);
}
