// Polynomials: every method reproduces quadratics exactly (they have no jerk,
// so the smoother's penalty is zero); cubics are exact for the not-a-knot spline
// everywhere and for the smoother in the interior, with a bounded bias at the ends.
#include <doctest/doctest.h>

#include <cmath>

#include "reference.hpp"
#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

namespace {
struct Worst {
  double p = 0, v = 0, a = 0;
};
// Largest errors over [begin, end) relative to the signal's own scales.
Worst errors(const Result& r, const Pva& t, std::size_t begin, std::size_t end) {
  return {max_error(r.pos, t.p, begin, end), max_error(r.vel, t.v, begin, end), max_error(r.acc, t.a, begin, end)};
}
}  // namespace

TEST_CASE("quadratics are exact for every method at every sample") {
  // x = 0.8 + 1.5 t - 2.5 t^2 (a = -5 m/s^2), with an offset away from zero.
  const Signal s = polynomial({0.8, 1.5, -2.5});
  for (double rate : kRates) {
    for (Method m : kMethods) {
      const double dt = 1.0 / rate;
      const std::size_t n = 50;
      const Result r = differentiate(sample(s, n, dt), dt, Params{.method = m});
      REQUIRE(r);
      const Worst w = errors(r, truth(s, n, dt), 0, n);
      CAPTURE(name(m));
      CAPTURE(rate);
      CHECK(w.p < 1e-12);
      CHECK(w.v < 1e-9);
      CHECK(w.a < 1e-7);
    }
  }
}

TEST_CASE("quadratics stay exact across gaps (Kalman methods)") {
  const Signal s = polynomial({-0.3, 0.7, 4.0});
  const double dt = 1.0 / 60;
  std::vector<double> y = sample(s, 40, dt);
  for (std::size_t k : {0u, 1u, 7u, 8u, 9u, 10u, 11u, 12u, 13u, 38u, 39u}) y[k] = std::nan("");
  for (Method m : {Method::kalman, Method::kalman_spline}) {
    const Result r = differentiate(y, dt, Params{.method = m});
    REQUIRE(r);
    const Worst w = errors(r, truth(s, 40, dt), 0, 40);
    CHECK(w.p < 1e-11);
    CHECK(w.v < 1e-9);
    CHECK(w.a < 1e-7);
  }
}

TEST_CASE("cubics: exact for the not-a-knot spline, central differences as their error term says") {
  // x = 0.2 - t + 0.5 t^2 + 3 t^3: jerk 18 m/s^3.
  const Signal s = polynomial({0.2, -1.0, 0.5, 3.0});
  for (double rate : kRates) {
    const double dt = 1.0 / rate;
    const std::size_t n = 60;
    const Pva t = truth(s, n, dt);
    const Result sp = differentiate(sample(s, n, dt), dt, Params{.method = Method::spline});
    const Worst ws = errors(sp, t, 0, n);
    CHECK(ws.v < 1e-9);
    CHECK(ws.a < 1e-7);
    // Central velocity errs by dt^2 x'''/6 inside and the one-sided one by -dt^2 x'''/3;
    // the second differences used are exact for cubics.
    const Result fd = differentiate(sample(s, n, dt), dt, Params{.method = Method::finite_difference});
    for (std::size_t k = 1; k + 1 < n; ++k) CHECK(fd.vel[k] - t.v[k] == doctest::Approx(dt * dt * 18.0 / 6.0));
    CHECK(fd.vel[0] - t.v[0] == doctest::Approx(-dt * dt * 18.0 / 3.0));
    CHECK(fd.vel[n - 1] - t.v[n - 1] == doctest::Approx(-dt * dt * 18.0 / 3.0));
    CHECK(errors(fd, t, 0, n).a < 1e-7);
  }
}

TEST_CASE("cubics: the smoother is exact in the interior, at the ends it bends them (jerk -> 0)") {
  // (Exact in the interior of an infinite series: its response is flat to 5th order at 0 Hz.)
  const Signal s = polynomial({0.2, -1.0, 0.5, 3.0});
  const double jerk = 18.0;
  for (double rate : kRates) {
    for (Method m : {Method::kalman, Method::kalman_spline}) {
      const double dt = 1.0 / rate;
      const std::size_t n = static_cast<std::size_t>(2.0 * rate);
      const std::size_t ends = static_cast<std::size_t>(kEndSeconds * rate);
      const Params params{.method = m};
      const Result r = differentiate(sample(s, n, dt), dt, params);
      REQUIRE(r);
      const Pva t = truth(s, n, dt);
      const Worst inner = errors(r, t, 2 * ends, n - 2 * ends);
      const Worst all = errors(r, t, 0, n);
      CAPTURE(name(m));
      CAPTURE(rate);
      // The end bias scales as jerk * tau (tau = 1 / (2 pi fc)) for acceleration, jerk * tau^2 for
      // velocity, and decays into the interior as exp(-d / (2 tau)): by 1e-4 half a second in.
      const double tau = 1.0 / (2.0 * 3.141592653589793 * params.cutoff_hz);
      CHECK(inner.v < 1e-3 * jerk * tau * tau);
      CHECK(inner.a < 1e-3 * jerk * tau);
      CHECK(all.a < 2.5 * jerk * tau);
      CHECK(all.v < 2.5 * jerk * tau * tau);
      CHECK(all.a > 0.5 * jerk * tau);  // the bias is real: ends are not interior
    }
  }
}

TEST_CASE("natural end conditions force zero acceleration at the ends (why not-a-knot is the default)") {
  const Signal s = polynomial({0.0, 0.0, -2.5});  // a = -5 everywhere
  const double dt = 1.0 / 120;
  const Result r =
      differentiate(sample(s, 40, dt), dt, Params{.method = Method::spline, .spline_end = SplineEnd::natural});
  REQUIRE(r);
  CHECK(r.acc[0] == doctest::Approx(0.0));
  CHECK(r.acc[39] == doctest::Approx(0.0));
  CHECK(std::abs(r.acc[20] + 5.0) < 1e-3);  // the disturbance decays by 2 - sqrt(3) per knot
  CHECK(std::abs(r.acc[1] + 5.0) > 1.0);
}
