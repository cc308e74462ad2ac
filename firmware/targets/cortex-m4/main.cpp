// tonus-band-f405: the band's firmware on the STM32F405. The core does the
// work; this file wires the register-level HAL to it and runs the main loop.
#include <array>

#include "board_hal.hpp"
#include "clock.hpp"
#include "console.hpp"
#include "otg_fs_dcd.hpp"
#include "probe.hpp"
#include "registers.hpp"
#include "tonus/firmware/device.hpp"
#include "tonus/usb/device_core.hpp"

namespace {

using namespace tonus;

f405::AdcDmaSampler g_sampler;
f405::BxCan g_can;
f405::FlashStorage g_storage;
f405::SysTickClock g_clock;
f405::Led g_led;
f405::Iwdg g_watchdog;
f405::NvicReset g_reset;
bool g_can_ok = false;
f405::OtgFsDcd g_dcd;

// Serial number: the 96-bit unique device id folded to 64 bits (RM0090 39.1);
// 0 where it cannot be read (QEMU).
std::uint64_t unique_id(bool& present) {
  std::array<std::uint32_t, 3> uid{};
  present = true;
  for (std::size_t k = 0; k < uid.size(); ++k) present = f405::probe_read(0x1FFF7A10U + 4U * k, uid[k]) && present;
  if (!present) return 0;
  return (static_cast<std::uint64_t>(uid[0] ^ uid[2]) << 32U) | uid[1];
}

const char* can_state(const f405::BxCan& can) {
  if (can.up()) return "up";
  switch (can.fault()) {
    case f405::CanFault::none: return "up";
    case f405::CanFault::no_crystal: return "off-no-crystal";
    case f405::CanFault::no_timing: return "off-no-timing";
    case f405::CanFault::no_bus: return "waiting-for-bus";
  }
  return "?";
}

void print_status(const fw::Device& device, const usb::DeviceCore& usb_hid, bool usb_ok) {
  using namespace f405::console;
  const proto::DeviceStats st = device.stats();
  print("status t_ms=");
  print_u(f405::micros() / 1000U);
  print(" reports=");
  print_u(st.reports_sent);
  print(" lost_blocks=");
  print_u(st.lost_blocks);
  print(" tx_dropped=");
  print_u(st.tx_dropped);
  print(" sampler=");
  print(device.sampler_stalled() ? "stalled" : "ok");
  print(" usb=");
  print(!usb_ok ? "off" : (usb_hid.connected() ? "configured" : "idle"));
  print(" can=");
  print(can_state(g_can));
  print("\n");
}

}  // namespace

extern "C" void DMA2_Stream0_IRQHandler() { g_sampler.on_dma_irq(); }
extern "C" void CAN1_TX_IRQHandler() { g_can.on_tx_irq(); }
extern "C" void CAN1_RX0_IRQHandler() { g_can.on_rx_irq(); }
extern "C" void OTG_FS_IRQHandler() { g_dcd.on_irq(); }

extern "C" void firmware_main() {
  using namespace f405::console;
  f405::systick_start();
  g_reset.latch_reset_cause();  // before the watchdog's init clears the flags
  g_watchdog.init();
  g_led.init();
  init();
  bool uid_present = false;
  const std::uint64_t serial = unique_id(uid_present);
  // A bus that is not there yet is retried; a clock CAN cannot use is final.
  g_can_ok = g_can.init(1) || g_can.fault() == f405::CanFault::no_bus;
  static usb::DeviceCore usb_hid(g_dcd, serial);
  g_dcd.attach(&usb_hid);
  const bool usb_ok = g_dcd.init();
  static hal::Board board{g_sampler,
                          g_clock,
                          g_storage,
                          g_led,
                          g_watchdog,
                          g_reset,
                          usb_ok ? &usb_hid : nullptr,
                          g_can_ok ? &g_can : nullptr,
                          serial,
                          1};
  static fw::Device device(board);
  device.boot();

  print("tonus-band ");
  print_u(fw::kFirmwareMajor);
  print(".");
  print_u(fw::kFirmwareMinor);
  print(".");
  print_u(fw::kFirmwarePatch);
  print(" boot clock=");
  print(f405::clocks().on_pll ? "hse-pll-168mhz" : "hsi-16mhz");
  print(" serial=");
  if (uid_present) {
    print_hex(serial);
  } else {
    print("none");
  }
  print(" watchdog_reset=");
  print(g_watchdog.caused_last_reset() ? "1" : "0");
  print(" storage=");
  print(fw::to_string(device.boot_load_result()));
  print(" usb=");
  print(usb_ok ? "ok" : "off");
  print(" can=");
  print(can_state(g_can));
  print("\n");

  std::uint64_t next_status_ms = 1000;
  for (;;) {
    device.poll();
    if (f405::micros() / 1000U >= next_status_ms) {
      next_status_ms += 1000;
      print_status(device, usb_hid, usb_ok);
    }
    asm volatile("wfi");  // the next DMA block (1 ms), CAN frame, USB event or SysTick wakes us
  }
}
