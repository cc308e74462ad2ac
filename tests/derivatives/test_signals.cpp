// Human-like signals: a Gaussian bump and minimum-jerk steps, clean and with
// noise; the smoothed acceleration error against the documented bounds.
#include <doctest/doctest.h>

#include <cmath>

#include "reference.hpp"
#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

TEST_CASE("clean human-like signals: bounded rounding of the acceleration, ends at rest exact") {
  struct Case {
    Signal s;
    double peak_acc, kalman_bound, spline_bound_120, fd_bound_120, fd_order;
  };
  // Bounds (docs/derivatives.md): the smoother rounds the corners of the minimum-jerk profile (its
  // jerk jumps) by about J tau whatever the rate; the spline converges as dt^2, differences as dt^2
  // on smooth signals but only as dt at the corners.
  const Case cases[] = {{min_jerk_step(0.5, 1.0, 0.5), 11.5, 2.2, 0.02, 0.35, 1.0},
                        {min_jerk_step(0.8, 1.0, 0.25), 74.0, 27.0, 0.5, 4.2, 1.0},
                        {gaussian_bump(0.1, 1.25, 0.1), 10.0, 0.3, 0.02, 0.02, 2.0}};
  for (const Case& c : cases) {
    for (double rate : kRates) {
      for (Method m : kMethods) {
        const Errors e = signal_errors(m, c.s, rate, 2.5);
        CAPTURE(name(m));
        CAPTURE(rate);
        CAPTURE(c.peak_acc);
        // The signals rest at both ends (the bump to 1e-5): every method is near-exact there.
        CHECK(e.acc_ends < 1e-4);
        if (m == Method::kalman || m == Method::kalman_spline) {
          CHECK(e.acc_interior <= c.kalman_bound);
        } else if (m == Method::spline) {
          CHECK(e.acc_interior <= c.spline_bound_120 * std::pow(120.0 / rate, 2.0) * 1.3);
        } else {
          CHECK(e.acc_interior <= c.fd_bound_120 * std::pow(120.0 / rate, c.fd_order) * 1.3);
        }
      }
    }
  }
}

TEST_CASE("with 2 mm noise the smoother's acceleration error is a small part of the peak") {
  // A foot step (peak 11.5 m/s^2) seen by optical mocap: kalman_spline keeps the RMS error near
  // (at most 1.5 m/s^2, 13 % of the peak), the raw spline and differences drown in noise.
  const Signal s = min_jerk_step(0.5, 1.0, 0.5);
  for (double rate : kRates) {
    const double dt = 1.0 / rate;
    const std::size_t n = static_cast<std::size_t>(2.5 * rate) + 1;
    std::vector<double> y = sample(s, n, dt);
    add_noise(y, 0.002, 42);
    const Pva t = truth(s, n, dt);
    const auto rms = [&](Method m) { return rms_error(differentiate(y, dt, Params{.method = m}).acc, t.a, 0, n); };
    CAPTURE(rate);
    const double ks = rms(Method::kalman_spline);
    CHECK(ks < 1.5);
    CHECK(rms(Method::spline) > 5.0 * ks);
    CHECK(rms(Method::finite_difference) > 3.0 * ks);
  }
}
