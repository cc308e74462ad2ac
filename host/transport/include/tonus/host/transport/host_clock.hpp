// The host clock every link event is stamped with: the steady clock
// (CLOCK_MONOTONIC), in microseconds. Time sync maps the band's clock onto it.
#pragma once

#include <chrono>
#include <cstdint>

namespace tonus::host {

inline std::int64_t steady_now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace tonus::host
