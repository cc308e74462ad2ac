// tonus-band-f405: the band's firmware on the STM32F405. The core does the
// work; this file wires the register-level HAL to it and runs the main loop.
#include "board_hal.hpp"
#include "clock.hpp"
#include "otg_fs_dcd.hpp"
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
f405::NvicReset g_reset(&g_can);
bool g_can_ok = false;
f405::OtgFsDcd g_dcd;

// Serial number: the 96-bit unique device id folded to 64 bits (RM0090 39.1).
std::uint64_t unique_id() {
  const auto* uid = reinterpret_cast<const volatile std::uint32_t*>(0x1FFF7A10);  // NOLINT(performance-no-int-to-ptr)
  return (static_cast<std::uint64_t>(uid[0] ^ uid[2]) << 32U) | uid[1];
}

}  // namespace

extern "C" void DMA2_Stream0_IRQHandler() { g_sampler.on_dma_irq(); }
extern "C" void CAN1_TX_IRQHandler() { g_can.on_tx_irq(); }
extern "C" void CAN1_RX0_IRQHandler() { g_can.on_rx_irq(); }
extern "C" void OTG_FS_IRQHandler() { g_dcd.on_irq(); }

extern "C" void firmware_main() {
  f405::systick_start();
  g_watchdog.init();
  g_led.init();
  g_can_ok = g_can.init(1);
  static usb::DeviceCore usb_hid(g_dcd, unique_id());
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
                          unique_id(),
                          1};
  static fw::Device device(board);
  device.boot();
  for (;;) {
    device.poll();
    asm volatile("wfi");  // the next DMA block (1 ms), CAN frame or USB event wakes us
  }
}
