// Cubic spline interpolation on a uniform grid, differentiated analytically at
// the knots (internal to the library).
#pragma once

#include <span>

#include "tonus/host/derivatives/params.hpp"

namespace tonus::derivatives::detail {

// First and second derivatives at the knots of the cubic spline through y
// (spacing h, y.size() >= kMinSamples). vel, acc and scratch hold y.size().
void cubic_spline_derivatives(std::span<const double> y, double h, SplineEnd end, std::span<double> vel,
                              std::span<double> acc, std::span<double> scratch);

}  // namespace tonus::derivatives::detail
