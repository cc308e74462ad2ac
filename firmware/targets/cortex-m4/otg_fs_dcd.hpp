// Device controller driver for the STM32F405 USB OTG FS core (Synopsys DWC2),
// device mode, full speed, internal PHY on PA11/PA12, no VBUS sensing
// (a bus-powered band). FIFOs (320 words): RX 128, EP0 TX 16, EP1 TX 16.
// The portable usb::DeviceCore above it does enumeration and HID.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "tonus/usb/dcd.hpp"
#include "tonus/usb/device_core.hpp"

namespace tonus::f405 {

class OtgFsDcd final : public usb::Dcd {
 public:
  void attach(usb::DeviceCore* core) { core_ = core; }
  // Clocks, pins, core reset, device mode, FIFOs, interrupts; then connects
  // (D+ pull-up). False if the core does not come out of reset.
  bool init();
  void on_irq();  // from OTG_FS_IRQHandler

  void set_address(std::uint8_t address) override;
  void configure_hid_endpoints(bool open) override;
  void ep0_send(std::span<const std::uint8_t> data, bool needs_zlp) override;
  void ep0_receive(std::size_t length) override;
  void ep0_status() override;
  void ep0_stall() override;
  bool hid_send(std::span<const std::uint8_t> packet) override;
  [[nodiscard]] bool hid_busy() const override;
  void hid_halt(bool in, bool halt) override;

 private:
  void bus_reset();
  void arm_ep0_out();
  void ep0_in_next();
  void arm_ep1_out();
  void receive_packet();
  void out_endpoint_events();
  void in_endpoint_events();

  usb::DeviceCore* core_ = nullptr;
  std::array<std::uint8_t, 8> setup_{};
  std::array<std::uint8_t, 64> ep0_rx_{};
  std::size_t ep0_rx_len_ = 0;
  bool ep0_expect_data_ = false;
  const std::uint8_t* ep0_tx_ = nullptr;
  std::size_t ep0_tx_left_ = 0;
  bool ep0_zlp_ = false;
  std::array<std::uint8_t, 64> ep1_rx_{};
  std::size_t ep1_rx_len_ = 0;
  volatile bool ep1_busy_ = false;
};

}  // namespace tonus::f405
