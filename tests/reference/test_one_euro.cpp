// The 1-euro filter against closed forms: a still tracker's noise shrinks as
// a first-order low-pass's does (variance ratio alpha / (2 - alpha)); at zero
// beta the step response is 1 - (1 - alpha)^n; a fast move raises the cutoff.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tonus/host/reference/one_euro.hpp"

namespace tonus::reference {
namespace {

using sim::Quat;
using sim::Vec3;

double alpha(double fc, double dt) { return 1.0 / (1.0 + 1.0 / (2.0 * std::numbers::pi * fc * dt)); }

TEST_CASE("1-euro: zero beta is a first-order low-pass (step response)") {
  OneEuroParams p;
  p.position_beta = 0.0;
  p.rotation_beta = 0.0;
  OneEuroState s;
  const double dt = 0.01;
  one_euro({Vec3::Zero(), Quat::Identity(), true}, dt, p, s);
  const double a = alpha(p.min_cutoff_hz, dt);
  const Quat turned(Eigen::AngleAxisd(0.4, Vec3::UnitZ()));
  for (int n = 1; n <= 50; ++n) {
    const TrackerPose out = one_euro({Vec3(1.0, 0.0, 0.0), turned, true}, dt, p, s);
    const double expected = 1.0 - std::pow(1.0 - a, n);
    CHECK(out.pos_m.x() == doctest::Approx(expected).epsilon(1e-12));
    // Slerp by the same share each step: the angle follows the same law.
    CHECK(out.rot.angularDistance(Quat::Identity()) == doctest::Approx(0.4 * expected).epsilon(1e-9));
  }
}

TEST_CASE("1-euro: a still tracker's noise shrinks as the low-pass's, a moving one lags little") {
  OneEuroParams p;
  OneEuroState s;
  const double dt = 1.0 / 90.0, sigma = 0.01;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, sigma);
  double sum2 = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const TrackerPose out = one_euro({Vec3(g(rng), 0.0, 0.0), Quat::Identity(), true}, dt, p, s);
    if (k > 100) sum2 += out.pos_m.x() * out.pos_m.x();
  }
  const double measured = std::sqrt(sum2 / (n - 101)) / sigma;
  // Noise alone moves the filter a little, raising the cutoff: between the
  // low-pass at min_cutoff and twice that.
  const double at_min = std::sqrt(alpha(p.min_cutoff_hz, dt) / (2.0 - alpha(p.min_cutoff_hz, dt)));
  const double at_twice = std::sqrt(alpha(2.0 * p.min_cutoff_hz, dt) / (2.0 - alpha(2.0 * p.min_cutoff_hz, dt)));
  MESSAGE("noise kept: " << measured << " (low-pass at min cutoff " << at_min << ")");
  CHECK(measured > at_min * 0.95);
  CHECK(measured < at_twice);

  // A hand moving at 2 m/s: the cutoff rises to min + beta * 2 = 5 Hz; the
  // steady lag of a first-order filter is speed / (2 pi fc).
  OneEuroState m;
  double lag = 0.0;
  for (int k = 0; k < 200; ++k) {
    const double x = 2.0 * k * dt;
    lag = x - one_euro({Vec3(x, 0.0, 0.0), Quat::Identity(), true}, dt, p, m).pos_m.x();
  }
  const double fc = p.min_cutoff_hz + p.position_beta * 2.0;
  CHECK(lag == doctest::Approx(2.0 * (1.0 / (2.0 * std::numbers::pi * fc) + 0.0)).epsilon(0.15));
  CHECK(lag < 2.0 / (2.0 * std::numbers::pi * p.min_cutoff_hz) / 3.0);  // far less than at the minimum cutoff
}

}  // namespace
}  // namespace tonus::reference
