// Parameter validation, errors as values, and the cutoff <-> jerk density map.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "tonus/host/derivatives/batch.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"

using namespace tonus::derivatives;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
const std::vector<double> kEight{0, 1, 2, 3, 4, 5, 6, 7};
}  // namespace

TEST_CASE("defaults are valid and every bad parameter is named") {
  CHECK(validate(Params{}, 1.0 / 120, 10));
  const auto check = [](Params p, double dt, std::size_t n, Error e) {
    CHECK(validate(p, dt, n).error == e);
    CHECK(differentiate(std::span(kEight).first(std::min<std::size_t>(n, 8)), dt, p).status.error == e);
  };
  for (double dt : {0.0, -0.01, kNaN, kInf}) check(Params{}, dt, 8, Error::bad_dt);
  for (double s : {0.0, -1.0, kNaN, kInf}) check(Params{.noise_sigma = s}, 0.01, 8, Error::bad_noise_sigma);
  for (double f : {0.0, -1.0, kNaN, kInf, 1e-6, 1e6}) check(Params{.cutoff_hz = f}, 0.01, 8, Error::bad_cutoff);
  for (double g : {-1.0, kNaN, kInf}) check(Params{.outlier_gate = g}, 0.01, 8, Error::bad_outlier_gate);
  check(Params{.method = static_cast<Method>(17)}, 0.01, 8, Error::bad_method);
  check(Params{.spline_end = static_cast<SplineEnd>(9)}, 0.01, 8, Error::bad_spline_end);
  for (Method m : {Method::kalman_spline, Method::kalman, Method::spline, Method::finite_difference}) {
    check(Params{.method = m}, 0.01, kMinSamples - 1, Error::too_few_samples);
    CHECK(differentiate(std::span(kEight).first(kMinSamples), 0.01, Params{.method = m}));
  }
  CHECK(!to_string(Error::bad_view).empty());
  CHECK(to_string(Error::bad_cutoff) == "bad_cutoff");
}

TEST_CASE("the Kalman methods need three finite samples, the others name the first non-finite one") {
  const std::vector<double> y{kNaN, 1.0, kInf, 2.0, kNaN, kNaN};
  for (Method m : {Method::kalman_spline, Method::kalman}) {
    CHECK(differentiate(y, 0.01, Params{.method = m}).status.error == Error::too_few_finite_samples);
  }
  const std::vector<double> z{0.0, 1.0, 2.0, 3.0, kInf, 5.0};
  for (Method m : {Method::spline, Method::finite_difference}) {
    const Result r = differentiate(z, 0.01, Params{.method = m});
    CHECK(r.status.error == Error::non_finite_sample);
    CHECK(r.status.index == 4);
    CHECK(r.pos.empty());
  }
}

TEST_CASE("bad views are refused, outputs may alias the input") {
  std::vector<double> x(kEight), out(8), shorter(7);
  CHECK(differentiate(Strided<const double>(nullptr, 8), 0.01, {}, {}).error == Error::bad_view);
  CHECK(differentiate(Strided<const double>(x.data(), 8), 0.01, {}, {.pos = {shorter.data(), 7}}).error ==
        Error::bad_view);
  CHECK(differentiate(Strided<const double>(x.data(), 8), 0.01, {}, {.vel = {out.data(), 8, 0}}).error ==
        Error::bad_view);
  // In place: positions written over the input.
  const Result ref = differentiate(x, 0.01);
  REQUIRE(differentiate(Strided<const double>(x.data(), 8), 0.01, {}, {.pos = {x.data(), 8}}));
  for (std::size_t i = 0; i < 8; ++i) CHECK(x[i] == ref.pos[i]);
}

TEST_CASE("jerk density and cutoff are inverse, the map is q = sigma^2 dt (2 pi fc)^6") {
  const double q = jerk_psd(0.002, 6.0, 1.0 / 120);
  CHECK(q == doctest::Approx(0.002 * 0.002 / 120 * std::pow(2 * std::numbers::pi * 6.0, 6)).epsilon(1e-14));
  CHECK(cutoff_from_jerk_psd(q, 0.002, 1.0 / 120) == doctest::Approx(6.0).epsilon(1e-13));
}

TEST_CASE("fixed-lag parameters are validated") {
  CHECK(FixedLag::create(0.01, {}, 10));
  CHECK(FixedLag::create(0.01, {}, FixedLag::kMaxLag));
  CHECK(FixedLag::create(0.01, {}, FixedLag::kMaxLag + 1).status.error == Error::bad_lag);
  CHECK(FixedLag::create(0.01, {.method = Method::spline}, 5).status.error == Error::bad_method);
  CHECK(FixedLag::create(0.0, {}, 5).status.error == Error::bad_dt);
  CHECK(!FixedLag::create(0.01, {.cutoff_hz = kNaN}, 5).smoother.has_value());
  CHECK(FixedLag3::create(0.01, {}, 3));
  CHECK(FixedLag3::create(0.01, {.noise_sigma = -1}, 3).status.error == Error::bad_noise_sigma);
}
