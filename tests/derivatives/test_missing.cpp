// Missing samples (NaN gaps) and fitting glitches (the outlier gate).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "reference.hpp"
#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

TEST_CASE("gaps are bridged smoothly and counted") {
  const double rate = 120, dt = 1.0 / rate;
  const std::size_t n = 480;
  const Signal s = sinusoid(0.1, 1.0, 0.2);
  const Pva t = truth(s, n, dt);
  std::vector<double> y = sample(s, n, dt);
  const Result full = differentiate(y, dt);
  for (std::size_t k = 200; k < 212; ++k) y[k] = kNaN;  // 100 ms gap
  y[0] = kNaN;
  y[n - 1] = std::numeric_limits<double>::infinity();
  const Result r = differentiate(y, dt);
  REQUIRE(r);
  CHECK(r.stats.missing == 14);
  CHECK(r.stats.longest_gap == 12);
  CHECK(r.stats.rejected == 0);
  // Across a 100 ms gap of a 1 Hz motion the bridge stays within 0.1 mm and 0.05 m/s^2 of the truth
  // and of the gap-free result; outside it nothing changes much.
  CHECK(max_error(r.pos, t.p, 195, 217) < 1e-4);
  CHECK(max_error(r.acc, t.a, 195, 217) < 0.05);
  CHECK(max_error(r.acc, full.acc, 195, 217) < 0.05);
  CHECK(max_error(r.acc, full.acc, 100, 150) < 1e-3);
  for (double v : r.acc) CHECK(std::isfinite(v));
}

TEST_CASE("a glitch: the gate drops it, without the gate it rings through the acceleration") {
  const double rate = 120, dt = 1.0 / rate;
  const std::size_t n = 300;
  const Signal s = min_jerk_step(0.5, 0.5, 0.5);
  const Pva t = truth(s, n, dt);
  std::vector<double> y = sample(s, n, dt);
  add_noise(y, 0.002, 3);
  y[150] += 0.1;  // a 10 cm fitting glitch (a marker swap) mid-step
  const Result off = differentiate(y, dt);
  const Result on = differentiate(y, dt, Params{.outlier_gate = 20.0});
  REQUIRE(on);
  CHECK(off.stats.rejected == 0);
  CHECK(on.stats.rejected == 1);
  const double err_off = max_error(off.acc, t.a, 140, 160), err_on = max_error(on.acc, t.a, 140, 160);
  MESSAGE("acc error near the glitch: " << err_off << " m/s^2 without the gate, " << err_on << " with");
  CHECK(err_off > 5.0);
  CHECK(err_on < 0.2 * err_off);
  CHECK(err_on < 1.0);
}

TEST_CASE("the gate gives up after kMaxGatedRun rejections in a row: a real jump is followed") {
  const double dt = 1.0 / 120;
  std::vector<double> y(240, 0.0);
  add_noise(y, 0.002, 9);
  for (std::size_t k = 120; k < 240; ++k) y[k] += 0.2;  // e.g. a marker relabelled for good
  const Result r = differentiate(y, dt, Params{.method = Method::kalman, .outlier_gate = 20.0});
  REQUIRE(r);
  // Rejected in runs of at most kMaxGatedRun while the filter converges to the new level.
  CHECK(r.stats.rejected >= kMaxGatedRun);
  CHECK(r.stats.rejected <= 6 * kMaxGatedRun);
  CHECK(std::abs(r.pos[200] - 0.2) < 0.005);
  CHECK(std::abs(r.pos[60]) < 0.005);
}

TEST_CASE("the recommended gate (20) stays quiet on clean motion with 2 mm noise, kicks included") {
  // A tighter gate trips on fast motion: the filter (causal) lags a jerky motion by about
  // jerk / (2 pi fc)^3, several innovation deviations for a kick (docs/derivatives.md).
  for (double rate : kRates) {
    for (const Signal& s : {min_jerk_step(0.5, 1.0, 0.5), sinusoid(0.2, 2.0, 0.0), gaussian_bump(0.1, 1.0, 0.1),
                            min_jerk_step(0.8, 1.0, 0.25)}) {
      const double dt = 1.0 / rate;
      std::vector<double> y = sample(s, static_cast<std::size_t>(2.5 * rate), dt);
      add_noise(y, 0.002, 17);
      const Result r = differentiate(y, dt, Params{.outlier_gate = 20.0});
      CAPTURE(rate);
      CHECK(r.stats.rejected == 0);
    }
  }
}
