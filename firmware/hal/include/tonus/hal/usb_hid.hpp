// HAL: the USB-HID endpoint pair. Input reports (stream, responses) go out on
// the interrupt IN endpoint, output reports (commands) arrive on interrupt OUT.
// Reports are the 64 bytes of tonus::proto::hid, report id first.
#pragma once

#include <cstddef>

#include "tonus/protocol/hid.hpp"

namespace tonus::hal {

class UsbHid {
 public:
  // The host has configured the device (reports would be read).
  [[nodiscard]] virtual bool connected() const = 0;
  // Queues an input report; false when it cannot be queued (the report is dropped).
  // A queued report goes out as soon as the interrupt IN endpoint is free.
  virtual bool send_input(const proto::hid::Report& report) = 0;
  // Moves queued input reports to the endpoint when it is free (main loop, every pass).
  virtual void service() = 0;
  // Every input report queued so far has been taken by the host.
  [[nodiscard]] virtual bool idle() const = 0;
  // Takes one pending output report; false if none. `length` is what arrived (<= 64).
  virtual bool receive_output(proto::hid::Report& report, std::size_t& length) = 0;

 protected:
  ~UsbHid() = default;
};

}  // namespace tonus::hal
