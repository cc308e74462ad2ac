// HAL: status LED, independent watchdog and system reset.
#pragma once

#include <cstdint>

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

 protected:
  ~SystemControl() = default;
};

}  // namespace tonus::hal
