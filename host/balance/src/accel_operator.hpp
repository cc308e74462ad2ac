// The analysis' acceleration operator: smoothing and differentiation are
// linear in the samples (no outlier gate), so a(x + dx) = a(x) + D dx; column j
// of D is the acceleration of a unit impulse at j. Kept as a band around the
// diagonal, as wide as an interior column's entries above a share of its peak.
#pragma once

#include <cstddef>
#include <vector>

#include "tonus/host/derivatives/params.hpp"

namespace tonus::balance::detail {

struct AccelOperator {
  std::size_t band = 0;
  std::size_t n = 0;
  std::vector<double> coef;  // coef[j * (2 band + 1) + (k + band - j)] = D[k][j]
  [[nodiscard]] double at(std::size_t k, std::size_t j) const {
    if (k + band < j || k > j + band) return 0.0;
    return coef[j * (2 * band + 1) + (k + band - j)];
  }
};

// D for n samples at dt. The operator is shift-invariant away from the ends:
// interior columns share one impulse response, and only the columns within
// two bands of an end are computed on their own (on a series four bands
// long, whose far end is then out of their reach), so the cost is
// O(band^2), not O(n^2).
AccelOperator accel_operator(std::size_t n, double dt, const derivatives::Params& params, double threshold = 1e-3);

}  // namespace tonus::balance::detail
