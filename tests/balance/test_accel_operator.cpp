// The balance filter's acceleration operator (host/balance/src/accel_operator.hpp)
// against the operator it stands for, built the slow way: column j is the
// differentiated unit impulse at j over the whole series. The banded, shift-
// invariant construction must agree within the band and, away from the ends,
// leave out only what is below its threshold.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "accel_operator.hpp"
#include "tonus/host/derivatives/batch.hpp"

using tonus::balance::detail::accel_operator;
using tonus::balance::detail::AccelOperator;

namespace {

void check_against_full(std::size_t n, double dt, double cutoff_hz) {
  tonus::derivatives::Params params;
  params.cutoff_hz = cutoff_hz;
  const AccelOperator op = accel_operator(n, dt, params);
  REQUIRE(op.n == n);
  REQUIRE(op.band > 0);
  double peak = 0.0, worst_inside = 0.0, worst_outside = 0.0, worst_outside_end = 0.0;
  std::vector<std::vector<double>> full(n);
  for (std::size_t j = 0; j < n; ++j) {
    std::vector<double> impulse(n, 0.0);
    impulse[j] = 1.0;
    const tonus::derivatives::Result r = tonus::derivatives::differentiate(impulse, dt, params);
    REQUIRE(r);
    full[j] = r.acc;
    for (const double v : r.acc) peak = std::max(peak, std::abs(v));
  }
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t k = 0; k < n; ++k) {
      const bool inside = k + op.band >= j && k <= j + op.band;
      const double err = std::abs(op.at(k, j) - full[j][k]);
      const bool end = j < 2 * op.band || j + 2 * op.band >= n;
      if (inside)
        worst_inside = std::max(worst_inside, err);
      else if (end)
        worst_outside_end = std::max(worst_outside_end, std::abs(full[j][k]));
      else
        worst_outside = std::max(worst_outside, std::abs(full[j][k]));
    }
  }
  INFO("n " << n << ", dt " << dt << ", cutoff " << cutoff_hz << " Hz: band " << op.band << ", peak " << peak
            << ", worst in band " << worst_inside / peak << ", largest left out " << worst_outside / peak
            << " (within two bands of an end " << worst_outside_end / peak << ")");
  CHECK(worst_inside <= 1e-6 * peak);
  CHECK(worst_outside <= 1e-3 * peak);
  // Near an end the smoother sees one side only and its response reaches
  // further than the interior's band: the Jacobian misses up to a few per cent
  // there (the residuals are always exact).
  CHECK(worst_outside_end <= 3e-2 * peak);
}

}  // namespace

TEST_CASE("balance: the banded acceleration operator matches the full impulse responses") {
  check_against_full(400, 1.0 / 120.0, 6.0);  // interior columns shared, ends computed apart
  check_against_full(400, 1.0 / 120.0, 4.0);
  check_against_full(300, 1.0 / 30.0, 12.0);
  check_against_full(40, 1.0 / 30.0, 6.0);  // short: every column on its own
}
