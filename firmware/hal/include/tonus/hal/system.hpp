// HAL: status LED, independent watchdog and system reset.
#pragma once

#include <cstdint>

#include "tonus/protocol/payloads.hpp"

namespace tonus::hal {

enum class LedPattern : std::uint8_t { off, booting, running, uncalibrated, calibrating, fault };

class StatusLed {
 public:
  virtual void show(LedPattern pattern) = 0;

 protected:
  ~StatusLed() = default;
};

class Watchdog {
 public:
  // Called once per healthy main-loop pass; a stalled loop lets the watchdog reset the chip.
  virtual void kick() = 0;
  // The last reset was caused by the watchdog.
  [[nodiscard]] virtual bool caused_last_reset() const = 0;

 protected:
  ~Watchdog() = default;
};

class SystemControl {
 public:
  // Reboots once pending transmissions have drained (the band: NVIC system reset).
  virtual void reset() = 0;
  // The stream's boot epoch: differs from the previous boot's so that a host
  // tells a reboot from late reports (docs/protocol.md section 2). Never 0 on a
  // board that implements it; 0 means "not told".
  [[nodiscard]] virtual std::uint8_t boot_epoch() const { return 0; }
  // Why this boot happened (the chip's reset flags, read before anything clears them).
  [[nodiscard]] virtual proto::ResetCause reset_cause() const { return proto::ResetCause::unknown; }
  // An update bootloader the band can reboot into (the STM32's USB DFU ROM).
  [[nodiscard]] virtual bool has_bootloader() const { return false; }
  // Reboots into it (called, like reset(), once the answer has drained).
  virtual void enter_bootloader() {}

 protected:
  ~SystemControl() = default;
};

}  // namespace tonus::hal
