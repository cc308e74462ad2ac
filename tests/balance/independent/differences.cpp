#include "independent/differences.hpp"

namespace tonus::indep {

std::vector<double> first_derivative(std::span<const double> x, double dt) {
  const std::size_t n = x.size();
  std::vector<double> d(n, 0.0);
  if (n < 3) return d;
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - x[i - 1]) / (2.0 * dt);
  d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / (2.0 * dt);
  d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / (2.0 * dt);
  return d;
}

std::vector<double> second_derivative(std::span<const double> x, double dt) {
  const std::size_t n = x.size();
  std::vector<double> d(n, 0.0);
  if (n < 3) return d;
  const double h2 = dt * dt;
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = (x[i + 1] - 2.0 * x[i] + x[i - 1]) / h2;
  if (n == 3) {
    d[0] = d[1];
    d[2] = d[1];
    return d;
  }
  d[0] = (2.0 * x[0] - 5.0 * x[1] + 4.0 * x[2] - x[3]) / h2;
  d[n - 1] = (2.0 * x[n - 1] - 5.0 * x[n - 2] + 4.0 * x[n - 3] - x[n - 4]) / h2;
  return d;
}

}  // namespace tonus::indep
