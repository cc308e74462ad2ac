// The portable USB device core of the band (chapter 9 + HID class), and the
// hal::UsbHid the firmware core streams through. Events come from the DCD's
// interrupt handler; the HAL methods run in the main loop. The OUT report
// queue is single-producer (interrupt) single-consumer (main loop).
//
// EP1 IN carries one 64-byte packet per 1 ms frame, shared by stream reports
// and command responses. Both wait in main-loop queues (the newest stream
// report, up to kResponseQueue responses) and service() loads the free
// endpoint: the stream first, except that a waiting response goes right after
// a stream report. At a report rate below 1 kHz (default 500 Hz) responses
// therefore ride in the free frames and cost no stream report; at 1 kHz each
// response makes one report wait, and a report replaced by a newer one before
// it could leave is counted (stream_superseded).
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
  // Bus suspend (3 ms idle) and resume: the configuration survives both
  // (USB 2.0 9.1.1.6); only a bus reset clears it.
  void on_suspend();
  void on_resume();

  // ---- hal::UsbHid (main loop)
  [[nodiscard]] bool connected() const override { return configured_.load() && !suspended_.load(); }
  bool send_input(const proto::hid::Report& report) override;
  void service() override;
  [[nodiscard]] bool idle() const override;
  bool receive_output(proto::hid::Report& report, std::size_t& length) override;

  [[nodiscard]] std::uint8_t address() const { return address_; }
  [[nodiscard]] std::uint32_t out_overflows() const { return out_overflows_; }
  [[nodiscard]] std::uint32_t suspends() const { return suspends_.load(); }
  [[nodiscard]] std::uint32_t resumes() const { return resumes_.load(); }
  [[nodiscard]] std::uint32_t stream_superseded() const { return stream_superseded_; }
  [[nodiscard]] bool in_halted() const { return in_halted_.load(); }

 private:
  void standard_request(const SetupPacket& s);
  void class_request(const SetupPacket& s);
  void get_descriptor(const SetupPacket& s);
  void reply(std::span<const std::uint8_t> data, std::uint16_t requested);
  void queue_output(std::span<const std::uint8_t> bytes);
  void feature(const SetupPacket& s, bool set);
  bool load(const proto::hid::Report& report);
  void forget_old_session();  // after a bus reset, drops what was queued for the old host

  Dcd& dcd_;
  std::uint64_t serial_;
  std::atomic<bool> configured_{false};
  std::atomic<bool> suspended_{false};
  std::atomic<bool> in_halted_{false};
  std::atomic<bool> out_halted_{false};
  std::atomic<std::uint32_t> suspends_{0};
  std::atomic<std::uint32_t> resumes_{0};
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

  // Input reports waiting for EP1 IN (main loop only).
  static constexpr std::size_t kResponseQueue = 4;
  proto::hid::Report stream_{};
  bool stream_waiting_ = false;
  std::array<proto::hid::Report, kResponseQueue> responses_{};
  std::size_t response_head_ = 0;
  std::size_t response_count_ = 0;
  bool last_was_stream_ = false;
  std::atomic<bool> drop_input_{false};  // set by a bus reset: queued reports were for the old session
  std::uint32_t stream_superseded_ = 0;

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
