// Fixed-lag smoothing: exactly the batch smoother of the data seen so far,
// the whole batch result once the stream ends, converging to the full batch
// result as the lag grows, and no allocation after create().
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>

#include "reference.hpp"
#include "support/allocation_counter.hpp"
#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<double> noisy_walk(double rate, std::size_t n, std::uint64_t seed) {
  std::vector<double> y = sample(min_jerk_step(0.5, 0.3, 0.5), n, 1.0 / rate);
  add_noise(y, 0.002, seed);
  return y;
}

// |a - b| in units of the signal: p, v dt, a dt^2.
double scaled(const Estimate& e, const Result& r, std::size_t i, double dt) {
  return std::max({std::abs(e.pos - r.pos[i]), std::abs(e.vel - r.vel[i]) * dt, std::abs(e.acc - r.acc[i]) * dt * dt});
}
}  // namespace

TEST_CASE("each output is the batch smoother of the samples pushed so far") {
  const double rate = 120, dt = 1.0 / rate;
  std::vector<double> y = noisy_walk(rate, 90, 1);
  y[1] = kNaN;
  for (std::size_t k = 40; k < 46; ++k) y[k] = kNaN;
  y[60] += 0.1;  // a glitch for the gate
  const Params params{.method = Method::kalman, .outlier_gate = 20.0};
  for (std::size_t lag : {0u, 1u, 2u, 5u, 10u, 20u}) {
    auto created = FixedLag::create(dt, params, lag);
    REQUIRE(created);
    FixedLag& f = *created.smoother;
    double worst = 0.0;
    std::size_t compared = 0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      const Estimate e = f.push(y[k]);
      CHECK(e.valid == (k >= lag && k >= 3));  // 3 finite samples (y[1] is missing), lag frames
      if (!e.valid || k + 1 < kMinSamples || k % 3 != 0) continue;
      const Result batch = differentiate(std::span(y).first(k + 1), dt, params);
      REQUIRE(batch);
      CHECK(e.index == k - lag);
      worst = std::max(worst, scaled(e, batch, e.index, dt));
      ++compared;
    }
    CAPTURE(lag);
    CHECK(compared > 20);
    CHECK(worst < 1e-10);
    CHECK(f.missing() == 7);
    CHECK(f.rejected() == 1);
  }
}

TEST_CASE("at the end of a stream, estimate(back) gives the rest of the batch result") {
  const double rate = 60, dt = 1.0 / rate;
  const std::vector<double> y = noisy_walk(rate, 80, 2);
  const std::size_t lag = 12;
  auto created = FixedLag::create(dt, {}, lag);
  REQUIRE(created);
  FixedLag& f = *created.smoother;
  std::vector<Estimate> out;
  for (double v : y) {
    const Estimate e = f.push(v);
    if (e.valid) out.push_back(e);
  }
  for (std::size_t back = lag; back-- > 0;) out.push_back(f.estimate(back));
  const Result batch = differentiate(y, dt, Params{.method = Method::kalman});
  REQUIRE(out.size() == y.size());  // every sample, once, in order
  double worst = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) CHECK(out[i].index == i);
  // The last push's output and the drained ones have seen every sample.
  for (std::size_t i = y.size() - lag - 1; i < y.size(); ++i) worst = std::max(worst, scaled(out[i], batch, i, dt));
  CHECK(worst < 1e-10);
  CHECK(!f.estimate(lag + 1).valid);  // not kept
}

TEST_CASE("estimate_window is estimate(back) for every back, to the bit, and invalid where estimate is") {
  const double dt = 1.0 / 120;
  std::vector<double> y = noisy_walk(120, 70, 7);
  y[30] = kNaN;
  const std::size_t lag = 12;
  auto f = FixedLag::create(dt, {}, lag).smoother;
  auto f3 = FixedLag3::create(dt, {}, lag).smoother;
  std::array<Estimate, lag + 3> window{};  // deeper than the lag: the extra ones invalid
  std::array<Estimate3, lag + 3> window3{};
  std::size_t compared = 0;
  for (const double v : y) {
    f->push(v);
    f3->push(Eigen::Vector3d(v, -2.0 * v, 0.5));
    f->estimate_window(window);
    f3->estimate_window(window3);
    for (std::size_t back = 0; back < window.size(); ++back) {
      const Estimate e = f->estimate(back);
      const Estimate3 e3 = f3->estimate(back);
      CHECK(window[back].valid == e.valid);
      CHECK(window3[back].valid == e3.valid);
      if (!e.valid) continue;
      CHECK(window[back].index == e.index);
      CHECK(window[back].pos == e.pos);
      CHECK(window[back].vel == e.vel);
      CHECK(window[back].acc == e.acc);
      CHECK(window3[back].acc == e3.acc);
      CHECK(window3[back].pos == e3.pos);
      ++compared;
    }
  }
  CHECK(compared > 500);
  f->estimate_window({});  // nothing asked: nothing done
}

TEST_CASE("the fixed-lag result converges to the full batch result as the lag grows") {
  // Documented look-ahead (docs/derivatives.md): with fc = 6 Hz the acceleration is within 10 % of
  // the noise of the batch result after 1/6 s of lag (5 frames at 30 Hz, 20 at 120 Hz).
  for (double rate : {30.0, 120.0}) {
    const double dt = 1.0 / rate;
    const std::size_t n = static_cast<std::size_t>(20 * rate);
    std::vector<double> y(n, 0.0);
    add_noise(y, 0.002, 5);
    const Result batch = differentiate(y, dt, Params{.method = Method::kalman});
    const double floor = rms_error(batch.acc, std::vector<double>(n, 0.0), 50, n - 50);
    double previous = 1e300;
    for (std::size_t lag : {0u, 2u, 5u, 10u, 20u}) {
      auto f = FixedLag::create(dt, {}, lag).smoother;
      std::vector<double> acc(n, 0.0);
      for (double v : y) {
        const Estimate e = f->push(v);
        if (e.valid) acc[e.index] = e.acc;
      }
      const double diff = rms_error(acc, batch.acc, 50, n - 50);
      CAPTURE(rate);
      CAPTURE(lag);
      CHECK(diff < previous);
      previous = diff;
      if (static_cast<double>(lag) * dt >= 0.15) CHECK(diff < 0.1 * floor);
      if (lag == 0) CHECK(diff > floor);  // the bare filter is far from the smoother
    }
  }
}

TEST_CASE("streaming outputs the smoother's states: within the noise of batch kalman_spline") {
  const double rate = 120, dt = 1.0 / rate;
  const std::vector<double> y = noisy_walk(rate, 240, 3);
  const Result k = differentiate(y, dt, Params{.method = Method::kalman});
  const Result ks = differentiate(y, dt, Params{.method = Method::kalman_spline});
  const double noise = predicted_noise(Params{}, dt).acc;
  CHECK(rms_error(k.acc, ks.acc, 30, 210) < 0.1 * noise);
}

TEST_CASE("reset forgets the stream, FixedLag3 is three FixedLag") {
  const double dt = 1.0 / 120;
  const std::vector<double> y = noisy_walk(120, 60, 4);
  auto one = FixedLag::create(dt, {}, 5).smoother;
  std::vector<Estimate> first(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) first[i] = one->push(y[i]);
  one->reset();
  CHECK(one->pushed() == 0);
  for (std::size_t i = 0; i < y.size(); ++i) {
    const Estimate e = one->push(y[i]);
    CHECK(e.valid == first[i].valid);
    CHECK(e.acc == first[i].acc);
  }
  auto three = FixedLag3::create(dt, {}, 5).smoother;
  auto x = FixedLag::create(dt, {}, 5).smoother;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const Estimate3 e3 = three->push(Eigen::Vector3d(0.0, y[i], 2.0 * y[i]));
    const Estimate e = x->push(y[i]);
    CHECK(e3.valid == e.valid);
    if (!e.valid) continue;
    CHECK(e3.index == e.index);
    CHECK(e3.acc.y() == e.acc);
    CHECK(e3.acc.z() == doctest::Approx(2.0 * e.acc));
    CHECK(std::abs(e3.acc.x()) < 1e-9);
  }
}

TEST_CASE("no allocation after create: 10,000 pushes with gaps and glitches") {
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  const double dt = 1.0 / 120;
  auto f = FixedLag::create(dt, Params{.outlier_gate = 20.0}, FixedLag::kMaxLag).smoother;
  auto f3 = FixedLag3::create(dt, {}, 10).smoother;
  std::vector<double> y = noisy_walk(120, 10000, 6);
  for (std::size_t k = 500; k < 10000; k += 700) y[k] = kNaN;
  double sink = 0.0;
  tonus::test::start_counting_allocations();
  for (double v : y) {
    sink += f->push(v).acc + f3->push(Eigen::Vector3d(v, -v, 0.5 * v)).acc.x();
    sink += f->estimate(3).vel;
  }
  const long allocations = tonus::test::stop_counting_allocations();
  CHECK(allocations == 0);
  CHECK(std::isfinite(sink));
}
