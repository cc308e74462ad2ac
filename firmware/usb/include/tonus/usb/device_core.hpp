// The portable USB device core of the band (chapter 9 + HID class), and the
// hal::UsbHid the firmware core streams through. Events come from the DCD's
// interrupt handler; the HAL methods run in the main loop. The OUT report
// queue is single-producer (interrupt) single-consumer (main loop).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "tonus/hal/usb_hid.hpp"
#include "tonus/usb/dcd.hpp"
#include "tonus/usb/descriptors.hpp"

namespace tonus::usb {

struct SetupPacket {
  std::uint8_t request_type = 0;
  std::uint8_t request = 0;
  std::uint16_t value = 0;
  std::uint16_t index = 0;
  std::uint16_t length = 0;
  static SetupPacket parse(std::span<const std::uint8_t, 8> raw);
};

class DeviceCore final : public hal::UsbHid {
 public:
  DeviceCore(Dcd& dcd, std::uint64_t serial) : dcd_(dcd), serial_(serial) {}

  // ---- events from the DCD (interrupt context)
  void on_bus_reset();
  void on_setup(std::span<const std::uint8_t, 8> raw);
  void on_ep0_data(std::span<const std::uint8_t> data);   // OUT data stage (SET_REPORT)
  void on_hid_out(std::span<const std::uint8_t> packet);  // EP1 OUT
  void on_suspend() { configured_.store(false); }

  // ---- hal::UsbHid (main loop)
  [[nodiscard]] bool connected() const override { return configured_.load(); }
  bool send_input(const proto::hid::Report& report) override;
  bool receive_output(proto::hid::Report& report, std::size_t& length) override;

  [[nodiscard]] std::uint8_t address() const { return address_; }
  [[nodiscard]] std::uint32_t out_overflows() const { return out_overflows_; }

 private:
  void standard_request(const SetupPacket& s);
  void class_request(const SetupPacket& s);
  void get_descriptor(const SetupPacket& s);
  void reply(std::span<const std::uint8_t> data, std::uint16_t requested);
  void queue_output(std::span<const std::uint8_t> bytes);

  Dcd& dcd_;
  std::uint64_t serial_;
  std::atomic<bool> configured_{false};
  std::uint8_t address_ = 0;
  std::uint8_t configuration_ = 0;
  std::uint8_t idle_rate_ = 0;
  std::uint8_t protocol_ = 1;  // report protocol
  std::array<std::uint8_t, 64> ep0_buffer_{};
  bool set_report_pending_ = false;

  // The last input report of each kind (stream, response) for GET_REPORT over
  // EP0: written by the main loop into the slot the interrupt is not told of,
  // then published, so the interrupt always copies a whole report.
  struct LastInput {
    std::array<proto::hid::Report, 2> slot{};
    std::atomic<std::uint8_t> published{0};
    std::atomic<bool> any{false};
  };
  std::array<LastInput, 2> last_input_{};  // [stream, response]

  static constexpr std::size_t kOutQueue = 8;
  struct OutReport {
    proto::hid::Report bytes{};
    std::size_t length = 0;
  };
  std::array<OutReport, kOutQueue> out_{};
  std::atomic<std::size_t> out_head_{0};  // written by the interrupt
  std::atomic<std::size_t> out_tail_{0};  // written by the main loop
  std::uint32_t out_overflows_ = 0;
};

}  // namespace tonus::usb
