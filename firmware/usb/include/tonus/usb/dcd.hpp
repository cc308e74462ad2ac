// Device controller driver (DCD) interface, TinyUSB-style: the only chip-
// specific part of the USB stack. The portable device core (device_core.hpp)
// answers control requests and drives the HID endpoints through it; the chip
// driver calls the core's event functions from its interrupt handler.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tonus::usb {

inline constexpr std::size_t kEp0Size = 64;
inline constexpr std::uint8_t kHidEndpoint = 1;  // EP1 IN (0x81) and EP1 OUT (0x01), interrupt, 64 bytes
inline constexpr std::size_t kHidPacket = 64;

class Dcd {
 public:
  // Applies the device address (Synopsys OTG: before the status stage).
  virtual void set_address(std::uint8_t address) = 0;
  // Opens (or, with false, closes) EP1 IN/OUT as 64-byte interrupt endpoints and arms OUT.
  virtual void configure_hid_endpoints(bool open) = 0;
  // Control IN data stage of `data` (the driver splits it into 64-byte packets,
  // adds a zero-length packet when needed), followed by the OUT status stage.
  // `data` must stay valid until the transfer completes.
  virtual void ep0_send(std::span<const std::uint8_t> data, bool needs_zlp) = 0;
  // Control OUT data stage of `length` bytes (delivered by DeviceCore::on_ep0_data).
  virtual void ep0_receive(std::size_t length) = 0;
  // Zero-length IN status stage of a request without data (or after an OUT data stage).
  virtual void ep0_status() = 0;
  // Refuses the request (STALL on EP0 until the next SETUP).
  virtual void ep0_stall() = 0;
  // Starts one IN transfer on EP1, copying the packet (into the TX FIFO) before
  // returning; false while the previous one is still in flight.
  virtual bool hid_send(std::span<const std::uint8_t> packet) = 0;
  // An IN packet is loaded and the host has not taken it yet.
  [[nodiscard]] virtual bool hid_busy() const = 0;
  // Sets or clears ENDPOINT_HALT on EP1 IN (`in`) or OUT. Clearing resets the
  // endpoint's data toggle to DATA0 (USB 2.0 9.4.5).
  virtual void hid_halt(bool in, bool halt) = 0;

 protected:
  ~Dcd() = default;
};

}  // namespace tonus::usb
