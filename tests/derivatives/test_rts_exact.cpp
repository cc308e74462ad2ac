// The RTS smoother is the exact MAP estimate of its model: it must agree with a
// dense least-squares solve of the same model (short series, gaps included)
// and, in the interior of a long series, with the model's exact frequency response.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "reference.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Largest difference in units of the signal scale: p, v dt, a dt^2 against max |y|.
double scaled_difference(const Result& r, const Pva& ref, double dt, double scale) {
  double d = 0.0;
  for (std::size_t k = 0; k < ref.p.size(); ++k) {
    d = std::max({d, std::abs(r.pos[k] - ref.p[k]), std::abs(r.vel[k] - ref.v[k]) * dt,
                  std::abs(r.acc[k] - ref.a[k]) * dt * dt});
  }
  return d / scale;
}
}  // namespace

TEST_CASE("RTS smoother equals the dense least-squares MAP estimate") {
  struct Case {
    double rate_hz, cutoff_hz;
    std::size_t n;
    std::vector<std::size_t> gaps;
  };
  const std::vector<Case> cases{{120, 6, 30, {}},
                                {30, 6, 24, {}},
                                {240, 2, 40, {}},
                                {24, 10, 12, {}},
                                {120, 8, 30, {0, 1, 2}},
                                {60, 6, 25, {10, 11, 12, 13, 14}},
                                {120, 6, 20, {17, 18, 19}},
                                {120, 6, 16, {0, 3, 7, 9}},
                                {1000, 1, 30, {}},
                                {50, 40, 20, {5}},
                                {100, 6, 4, {}}};
  std::uint64_t seed = 1;
  for (const Case& c : cases) {
    const double dt = 1.0 / c.rate_hz;
    std::vector<double> y = sample(sinusoid(0.3, 1.7, 0.4), c.n, dt);
    for (double& v : y) v += 1.2;  // an offset, as real positions have
    add_noise(y, 0.004, seed++);
    for (std::size_t g : c.gaps) y[g] = kNaN;
    const Params params{.method = Method::kalman, .noise_sigma = 0.002, .cutoff_hz = c.cutoff_hz};
    const Result r = differentiate(y, dt, params);
    REQUIRE(r);
    const Pva ref = dense_map(y, dt, params.noise_sigma, jerk_psd(params.noise_sigma, params.cutoff_hz, dt));
    const double d = scaled_difference(r, ref, dt, 1.5);
    CAPTURE(c.rate_hz);
    CAPTURE(c.cutoff_hz);
    CAPTURE(c.n);
    CHECK(d < 1e-9);
    MESSAGE("rate " << c.rate_hz << " fc " << c.cutoff_hz << " n " << c.n << ": " << d);
  }
}

TEST_CASE("interior of a long series follows the exact frequency response of the model") {
  for (double rate : {30.0, 60.0, 120.0, 240.0}) {
    for (double f : {0.5, 2.0, 5.0, 9.0}) {
      const double dt = 1.0 / rate;
      const std::size_t n = static_cast<std::size_t>(8.0 * rate);
      const double theta = 2.0 * std::numbers::pi * f * dt;
      const std::vector<double> y = sample(sinusoid(0.1, f, 0.3), n, dt);
      const Params params{};
      const double q = jerk_psd(params.noise_sigma, params.cutoff_hz, dt);
      for (Method m : {Method::kalman, Method::kalman_spline}) {
        const Result r = differentiate(y, dt, Params{.method = m});
        REQUIRE(r);
        const Response h = m == Method::kalman ? kalman_response(theta, dt, params.noise_sigma, q)
                                               : kalman_spline_response(theta, dt, params.noise_sigma, q);
        double dp = 0.0, dv = 0.0, da = 0.0;
        const double w = 2 * std::numbers::pi * f;
        for (std::size_t k = n / 2 - 20; k < n / 2 + 20; ++k) {
          const std::complex<double> z = 0.1 * std::polar(1.0, theta * static_cast<double>(k) + 0.3);
          dp = std::max(dp, std::abs(r.pos[k] - (h.p * z).imag()));
          dv = std::max(dv, std::abs(r.vel[k] - (h.v * z).imag()) / w);
          da = std::max(da, std::abs(r.acc[k] - (h.a * z).imag()) / (w * w));
        }
        MESSAGE("rate " << rate << " f " << f << " method " << static_cast<int>(m) << ": " << dp << " " << dv << " "
                        << da);
        CHECK(std::max({dp, dv, da}) < 1e-9);
      }
    }
  }
}
