#include "accel_operator.hpp"

#include <algorithm>
#include <cmath>

#include "tonus/host/derivatives/batch.hpp"

namespace tonus::balance::detail {
namespace {

// Acceleration response of an impulse at j in a series of length len.
std::vector<double> response(std::size_t len, std::size_t j, double dt, const derivatives::Params& params) {
  std::vector<double> impulse(len, 0.0);
  impulse[j] = 1.0;
  derivatives::Result r = derivatives::differentiate(impulse, dt, params);
  if (!r) return std::vector<double>(len, 0.0);
  return std::move(r.acc);
}

}  // namespace

AccelOperator accel_operator(std::size_t n, double dt, const derivatives::Params& params, double threshold) {
  AccelOperator op;
  op.n = n;
  if (n == 0) return op;
  // The band, from an impulse in the middle of a series long enough for the
  // response to die out (4 s is beyond any cutoff the analysis accepts above 1 Hz).
  const std::size_t probe_len = std::min(n, static_cast<std::size_t>(std::ceil(4.0 / dt)) | 1U);
  const std::size_t mid = probe_len / 2;
  const std::vector<double> probe = response(probe_len, mid, dt, params);
  double peak = 0.0;
  for (const double v : probe) peak = std::max(peak, std::abs(v));
  for (std::size_t k = 0; k < probe_len; ++k) {
    if (std::abs(probe[k]) > threshold * peak) op.band = std::max(op.band, k > mid ? k - mid : mid - k);
  }
  op.band = std::min(op.band, n - 1);
  const std::size_t b = op.band, w = 2 * b + 1;
  op.coef.assign(n * w, 0.0);
  const auto store = [&](std::size_t j, const std::vector<double>& acc, std::size_t offset) {
    // acc[i] is the response at sample offset + i.
    const std::size_t lo = j > b ? j - b : 0, hi = std::min(n, j + b + 1);
    for (std::size_t k = lo; k < hi; ++k) {
      if (k >= offset && k - offset < acc.size()) op.coef[j * w + (k + b - j)] = acc[k - offset];
    }
  };
  const std::size_t len = 4 * b + 1;
  if (n <= len + 2 * b) {  // short: every column on its own
    for (std::size_t j = 0; j < n; ++j) store(j, response(n, j, dt, params), 0);
    return op;
  }
  for (std::size_t j = 0; j < 2 * b; ++j) store(j, response(len, j, dt, params), 0);
  for (std::size_t j = n - 2 * b; j < n; ++j) store(j, response(len, j - (n - len), dt, params), n - len);
  const std::vector<double> interior = response(len, 2 * b, dt, params);
  for (std::size_t j = 2 * b; j < n - 2 * b; ++j) store(j, interior, j - 2 * b);
  return op;
}

}  // namespace tonus::balance::detail
