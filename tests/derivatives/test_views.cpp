// Strided views and the Vec3 convenience: the same numbers as the scalar path.
#include <doctest/doctest.h>

#include <cmath>

#include "reference.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

TEST_CASE("points are processed per coordinate, in place through strides") {
  const double dt = 1.0 / 120;
  const std::size_t n = 100;
  std::vector<double> xs = sample(sinusoid(0.2, 1.0, 0.0), n, dt), ys = sample(min_jerk_step(0.3, 0.2, 0.4), n, dt),
                      zs = sample(gaussian_bump(0.1, 0.4, 0.1), n, dt);
  add_noise(xs, 0.002, 1);
  ys[30] = std::nan("");
  std::vector<Eigen::Vector3d> points(n);
  for (std::size_t i = 0; i < n; ++i) points[i] = {xs[i], ys[i], zs[i]};
  for (Method m : {Method::kalman_spline, Method::kalman}) {
    const Params p{.method = m};
    const Result3 r3 = differentiate(std::span<const Eigen::Vector3d>(points), dt, p);
    REQUIRE(r3);
    CHECK(r3.stats.missing == 1);
    CHECK(r3.stats.longest_gap == 1);
    const Result rx = differentiate(xs, dt, p), ry = differentiate(ys, dt, p), rz = differentiate(zs, dt, p);
    for (std::size_t i = 0; i < n; ++i) {
      CHECK(r3.acc[i].x() == rx.acc[i]);
      CHECK(r3.acc[i].y() == ry.acc[i]);
      CHECK(r3.vel[i].z() == rz.vel[i]);
      CHECK(r3.pos[i].y() == ry.pos[i]);
    }
  }
  // Non-finite points are refused by the raw spline, with the sample's index.
  const Result3 bad = differentiate(std::span<const Eigen::Vector3d>(points), dt, Params{.method = Method::spline});
  CHECK(bad.status.error == Error::non_finite_sample);
  CHECK(bad.status.index == 30);
  CHECK(bad.acc.empty());
  // A strided output into a caller's array: only acceleration, into column 2 of a 4-wide table.
  std::vector<double> table(4 * n, -1.0);
  REQUIRE(differentiate(coordinate(std::span<const Eigen::Vector3d>(points), 0), dt, {},
                        {.acc = {table.data() + 2, n, 4}}));
  const Result rx = differentiate(xs, dt);
  for (std::size_t i = 0; i < n; ++i) {
    CHECK(table[4 * i + 2] == rx.acc[i]);
    CHECK(table[4 * i] == -1.0);
  }
  CHECK(differentiate(std::span<const Eigen::Vector3d>(), dt).status.error == Error::too_few_samples);
}
