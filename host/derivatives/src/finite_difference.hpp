// Finite differences (internal to the library): the baseline method.
#pragma once

#include <span>

namespace tonus::derivatives::detail {

// Central differences in the interior, second-order one-sided ones at the ends
// (exact for quadratics; the end second difference is exact for cubics).
// y.size() >= kMinSamples; vel and acc hold y.size().
void finite_differences(std::span<const double> y, double h, std::span<double> vel, std::span<double> acc);

}  // namespace tonus::derivatives::detail
