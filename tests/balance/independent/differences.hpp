// Finite differences of evenly sampled signals: central inside, one-sided
// (second-order accurate) at the ends. All are exact for quadratics.
#pragma once

#include <span>
#include <vector>

namespace tonus::indep {

// (x[i+1] - x[i-1]) / (2 dt); at the ends (-3 x0 + 4 x1 - x2) / (2 dt) and its
// mirror. Fewer than 3 samples: zeros.
[[nodiscard]] std::vector<double> first_derivative(std::span<const double> x, double dt);

// (x[i+1] - 2 x[i] + x[i-1]) / dt^2; at the ends (2 x0 - 5 x1 + 4 x2 - x3) / dt^2
// and its mirror (exact for cubics too), or the one second difference there
// is for 3 samples. Fewer than 3 samples: zeros.
[[nodiscard]] std::vector<double> second_derivative(std::span<const double> x, double dt);

}  // namespace tonus::indep
