#include "spline.hpp"

#include <cstddef>

namespace tonus::derivatives::detail {

// Second derivatives M at the knots solve, for the interior knots i,
//   M[i-1] + 4 M[i] + M[i+1] = 6 (y[i+1] - 2 y[i] + y[i-1]) / h^2      (C2 continuity).
// Not-a-knot (M[0] = 2 M[1] - M[2], likewise at the end) turns the first and
// last rows into 6 M[1] = ..., natural ends set M[0] = M[n-1] = 0. The system is
// diagonally dominant: Thomas' algorithm without pivoting is stable.
void cubic_spline_derivatives(std::span<const double> y, double h, SplineEnd end, std::span<double> vel,
                              std::span<double> acc, std::span<double> scratch) {
  const std::size_t n = y.size();
  const bool nak = end == SplineEnd::not_a_knot;
  std::span<double> m = acc;       // the solution, in place
  std::span<double> cp = scratch;  // modified super-diagonal
  const double k = 6.0 / (h * h);
  // Forward sweep over rows 1..n-2.
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const bool first = i == 1, last = i + 2 == n;
    const double a = (first || (last && nak)) ? 0.0 : 1.0;
    const double b = (nak && (first || last)) ? 6.0 : 4.0;
    const double c = (last || (first && nak)) ? 0.0 : 1.0;
    const double rhs = k * (y[i + 1] - 2.0 * y[i] + y[i - 1]);
    const double denom = b - (first ? 0.0 : a * cp[i - 1]);
    cp[i] = c / denom;
    m[i] = (rhs - (first ? 0.0 : a * m[i - 1])) / denom;
  }
  for (std::size_t i = n - 2; i-- > 1;) m[i] -= cp[i] * m[i + 1];
  if (nak) {
    m[0] = 2.0 * m[1] - m[2];
    m[n - 1] = 2.0 * m[n - 2] - m[n - 3];
  } else {
    m[0] = 0.0;
    m[n - 1] = 0.0;
  }
  // Slopes from the segment to the right (the last knot: from its left segment).
  for (std::size_t i = 0; i + 1 < n; ++i) vel[i] = (y[i + 1] - y[i]) / h - h * (2.0 * m[i] + m[i + 1]) / 6.0;
  vel[n - 1] = (y[n - 1] - y[n - 2]) / h + h * (m[n - 2] + 2.0 * m[n - 1]) / 6.0;
}

}  // namespace tonus::derivatives::detail
