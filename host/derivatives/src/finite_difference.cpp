#include "finite_difference.hpp"

#include <cstddef>

namespace tonus::derivatives::detail {

void finite_differences(std::span<const double> y, double h, std::span<double> vel, std::span<double> acc) {
  const std::size_t n = y.size();
  const double h2 = h * h;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    vel[i] = (y[i + 1] - y[i - 1]) / (2.0 * h);
    acc[i] = (y[i + 1] - 2.0 * y[i] + y[i - 1]) / h2;
  }
  vel[0] = (-3.0 * y[0] + 4.0 * y[1] - y[2]) / (2.0 * h);
  vel[n - 1] = (3.0 * y[n - 1] - 4.0 * y[n - 2] + y[n - 3]) / (2.0 * h);
  acc[0] = (2.0 * y[0] - 5.0 * y[1] + 4.0 * y[2] - y[3]) / h2;
  acc[n - 1] = (2.0 * y[n - 1] - 5.0 * y[n - 2] + 4.0 * y[n - 3] - y[n - 4]) / h2;
}

}  // namespace tonus::derivatives::detail
