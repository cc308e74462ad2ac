// Throughput of tonus::derivatives: batch smoothing and differentiation per
// method (samples per second, one coordinate) and the fixed-lag push per lag.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include "tonus/host/derivatives/batch.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"

namespace {

using tonus::derivatives::Method;

// A 120 Hz walk-like coordinate with 2 mm noise.
std::vector<double> series(std::size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> y(n);
  for (std::size_t k = 0; k < n; ++k) y[k] = 0.3 * std::sin(2.0 * static_cast<double>(k) / 120.0) + noise(rng);
  return y;
}

void BM_Batch(benchmark::State& state, Method method) {
  const std::vector<double> y = series(static_cast<std::size_t>(state.range(0)));
  const tonus::derivatives::Params params{.method = method};
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    auto r = tonus::derivatives::differentiate(y, 1.0 / 120, params);
    benchmark::DoNotOptimize(r.acc.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK_CAPTURE(BM_Batch, kalman_spline, Method::kalman_spline)->Arg(10000);
BENCHMARK_CAPTURE(BM_Batch, kalman, Method::kalman)->Arg(10000);
BENCHMARK_CAPTURE(BM_Batch, spline, Method::spline)->Arg(10000);
BENCHMARK_CAPTURE(BM_Batch, finite_difference, Method::finite_difference)->Arg(10000);

void BM_FixedLagPush(benchmark::State& state) {
  const std::vector<double> y = series(4096);
  auto f = tonus::derivatives::FixedLag::create(1.0 / 120, {}, static_cast<std::size_t>(state.range(0))).smoother;
  std::size_t k = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const auto e = f->push(y[k++ & 4095]);
    benchmark::DoNotOptimize(e.acc);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FixedLagPush)->Arg(0)->Arg(10)->Arg(20)->Arg(120);

}  // namespace

BENCHMARK_MAIN();
