// Everything the core needs from a board, handed to tonus::fw::Device.
// USB-HID and CAN are optional: a board without one passes nullptr.
#pragma once

#include <cstdint>

#include "tonus/hal/can_port.hpp"
#include "tonus/hal/clock.hpp"
#include "tonus/hal/emg_sampler.hpp"
#include "tonus/hal/storage.hpp"
#include "tonus/hal/system.hpp"
#include "tonus/hal/usb_hid.hpp"

namespace tonus::hal {

struct Board {
  EmgSampler& emg;
  Clock& clock;
  Storage& storage;
  StatusLed& led;
  Watchdog& watchdog;
  SystemControl& system;
  UsbHid* hid = nullptr;
  CanPort* can = nullptr;
  std::uint64_t serial = 0;
  std::uint8_t hardware_revision = 0;
};

}  // namespace tonus::hal
