// The smoothstep ramp: 0 below 0, 1 above 1, and 3x^2 - 2x^3 between
// (zero slope at both ends), for eases and blends.
#pragma once

#include <algorithm>

namespace tonus::reference::detail {

inline double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace tonus::reference::detail
