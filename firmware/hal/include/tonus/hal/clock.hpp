// HAL: monotonic microsecond clock (never wraps in practice: 64 bits).
#pragma once

#include <cstdint>

namespace tonus::hal {

class Clock {
 public:
  [[nodiscard]] virtual std::uint64_t now_us() const = 0;

 protected:
  ~Clock() = default;
};

}  // namespace tonus::hal
