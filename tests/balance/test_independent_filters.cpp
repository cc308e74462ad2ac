// The independent estimator's numerical parts against closed forms: the
// Butterworth filter's zero-lag gain, exact differences of polynomials, and
// the support polygon's hull and distances.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "independent/butterworth.hpp"
#include "independent/differences.hpp"
#include "independent/hull.hpp"

using namespace tonus::indep;

namespace {

constexpr double kRate = 120.0, kCutoff = 6.0;

// Amplitude and phase (radians) of the f Hz component of x over [from, to),
// by least squares on sin and cos (the span holds whole periods).
std::pair<double, double> component(const std::vector<double>& x, double f, std::size_t from, std::size_t to) {
  double ss = 0, sc = 0, cc = 0, xs = 0, xc = 0;
  for (std::size_t i = from; i < to; ++i) {
    const double w = 2.0 * std::numbers::pi * f * static_cast<double>(i) / kRate;
    const double s = std::sin(w), c = std::cos(w);
    ss += s * s, sc += s * c, cc += c * c, xs += x[i] * s, xc += x[i] * c;
  }
  const double det = ss * cc - sc * sc;
  const double a = (xs * cc - xc * sc) / det, b = (xc * ss - xs * sc) / det;  // x = a sin + b cos
  return {std::hypot(a, b), std::atan2(b, a)};
}

std::vector<double> filtered_sine(double f) {
  std::vector<double> x(1200);  // 10 s
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] = std::sin(2.0 * std::numbers::pi * f * static_cast<double>(i) / kRate);
  return filtfilt(butterworth_lowpass(kCutoff, kRate), x);
}

}  // namespace

TEST_CASE("independent ZMP: Butterworth: unit gain at DC, a constant passes untouched") {
  const Biquad b = butterworth_lowpass(kCutoff, kRate);
  CHECK((b.b0 + b.b1 + b.b2) / (1.0 + b.a1 + b.a2) == doctest::Approx(1.0).epsilon(1e-14));
  const std::vector<double> y = filtfilt(b, std::vector<double>(50, 3.25));
  for (const double v : y) CHECK(v == doctest::Approx(3.25).epsilon(1e-12));
  CHECK(filtfilt(b, std::vector<double>{2.0}) == std::vector<double>{2.0});  // too short to filter
}

TEST_CASE(
    "independent ZMP: Butterworth filtfilt: no lag, gain |H|^2 = 1 / (1 + (f / fc)^4): 1 below cutoff, 0.5 at it") {
  // Whole periods in the middle 8 s, away from the padded ends.
  for (const double f : {0.5, 1.0, 3.0, 6.0, 12.0}) {
    const auto [amplitude, phase] = component(filtered_sine(f), f, 60, 1020);
    const double analog = 1.0 / (1.0 + std::pow(f / kCutoff, 4));
    MESSAGE(f << " Hz: gain " << amplitude << " (analog prototype " << analog << "), phase " << phase << " rad");
    CHECK(std::abs(phase) < 1e-6);
    CHECK(amplitude == doctest::Approx(butterworth_power_gain(f, kCutoff, kRate)).epsilon(1e-4));
    if (f <= 1.0) CHECK(amplitude == doctest::Approx(1.0).epsilon(0.01));
    if (f <= kCutoff) CHECK(amplitude == doctest::Approx(analog).epsilon(0.01));  // the bilinear warp is small here
  }
  CHECK(butterworth_power_gain(kCutoff, kCutoff, kRate) == doctest::Approx(0.5).epsilon(1e-14));
  CHECK(component(filtered_sine(kCutoff), kCutoff, 60, 1020).first == doctest::Approx(0.5).epsilon(0.01));
}

TEST_CASE(
    "independent ZMP: finite differences: exact for a quadratic (and the acceleration for a cubic), ends included") {
  const double dt = 0.01;
  std::vector<double> quad(25), cubic(25);
  for (std::size_t i = 0; i < quad.size(); ++i) {
    const double t = static_cast<double>(i) * dt;
    quad[i] = 3.0 + 2.0 * t - 4.5 * t * t;
    cubic[i] = quad[i] + 7.0 * t * t * t;
  }
  const std::vector<double> v = first_derivative(quad, dt), a = second_derivative(quad, dt);
  const std::vector<double> ac = second_derivative(cubic, dt);
  for (std::size_t i = 0; i < quad.size(); ++i) {
    const double t = static_cast<double>(i) * dt;
    CHECK(v[i] == doctest::Approx(2.0 - 9.0 * t).epsilon(1e-9).scale(1.0));
    CHECK(a[i] == doctest::Approx(-9.0).epsilon(1e-7));
    CHECK(ac[i] == doctest::Approx(-9.0 + 42.0 * t).epsilon(1e-7).scale(1.0));
  }
  // Three samples: the one second difference; fewer: zeros, no reading past the end.
  CHECK(second_derivative(std::vector<double>{0.0, 1.0, 4.0}, 1.0) == std::vector<double>{2.0, 2.0, 2.0});
  CHECK(first_derivative(std::vector<double>{1.0, 2.0}, 1.0) == std::vector<double>{0.0, 0.0});
}

TEST_CASE("independent ZMP: support polygon: monotone-chain hull and signed distance") {
  const std::vector<Point2> square = convex_hull({{0, 0}, {0.3, 0}, {0.3, 0.1}, {0, 0.1}, {0.1, 0.05}, {0.3, 0.05}});
  REQUIRE(square.size() == 4);
  CHECK(signed_distance(square, {0.15, 0.05}) == doctest::Approx(-0.05));
  CHECK(signed_distance(square, {0.29, 0.05}) == doctest::Approx(-0.01));
  CHECK(signed_distance(square, {0.4, 0.05}) == doctest::Approx(0.1));
  CHECK(signed_distance(square, {0.4, 0.2}) == doctest::Approx(std::hypot(0.1, 0.1)));
  CHECK(signed_distance(square, {0.3, 0.02}) == doctest::Approx(0.0).scale(1.0));
  // Degenerate hulls: a point and a segment (collinear points) have no inside.
  CHECK(convex_hull({{1, 1}, {1, 1}}).size() == 1);
  const std::vector<Point2> segment = convex_hull({{0, 0}, {0.5, 0}, {1, 0}});
  REQUIRE(segment.size() == 2);
  CHECK(signed_distance(segment, {0.5, 0.0}) == doctest::Approx(0.0).scale(1.0));
  CHECK(signed_distance(segment, {1.3, 0.4}) == doctest::Approx(0.5));
  CHECK(signed_distance(convex_hull({{2, 2}}), {2, 3}) == doctest::Approx(1.0));
  CHECK(std::isinf(signed_distance({}, {0, 0})));
  // Non-finite points are dropped, not sorted.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(convex_hull({{0, 0}, {nan, 1}, {1, 0}, {0, 1}}).size() == 3);
}
