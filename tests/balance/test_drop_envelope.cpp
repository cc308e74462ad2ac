// The pelvis's drop eased over time (host/balance/src/drop_envelope.hpp):
// never below a frame's need, nothing where no need is near, and a need alone
// eased in and out with a small acceleration, against the one-frame jolt it
// replaces.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "drop_envelope.hpp"

namespace tonus::balance {
namespace {

double largest_acceleration(const std::vector<double>& d, double dt) {
  double a = 0.0;
  for (std::size_t t = 1; t + 1 < d.size(); ++t)
    a = std::max(a, std::abs(d[t + 1] - 2.0 * d[t] + d[t - 1]) / (dt * dt));
  return a;
}

TEST_CASE("drop envelope: at least every need, nothing beyond its reach, zero where none is needed") {
  for (const double hz : {30.0, 60.0, 120.0}) {
    const detail::DropEnvelope env(1.0 / hz);
    CAPTURE(hz);
    // Sparse, bursty needs of up to 8 mm, as straight legs give them.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> size(0.0, 0.008);
    std::bernoulli_distribution some(0.15);
    std::vector<double> need(600, 0.0);
    for (double& v : need) v = some(rng) ? size(rng) : 0.0;
    const std::vector<double> d = env.smooth(need);
    REQUIRE(d.size() == need.size());
    for (std::size_t t = 0; t < need.size(); ++t) {
      CHECK(d[t] >= need[t] - 1e-15);
      CHECK(d[t] == doctest::Approx(env.at(need.data(), need.size(), t)).epsilon(1e-15));
    }
    // None needed: exactly none.
    const std::vector<double> none = env.smooth(std::vector<double>(200, 0.0));
    CHECK(std::all_of(none.begin(), none.end(), [](double v) { return v == 0.0; }));
    // One need reaches reach() frames either side and no further; the reach
    // fits the online filter's look-ahead (0.25 s, in whole frames).
    std::vector<double> one(200, 0.0);
    one[100] = 0.005;
    const std::vector<double> e = env.smooth(one);
    const std::size_t r = env.reach();
    CHECK(static_cast<double>(r) <= std::round(0.25 * hz));
    CHECK(e[100 - r] > 0.0);
    CHECK(e[100 + r] > 0.0);
    CHECK(e[100 - r - 1] == 0.0);
    CHECK(e[100 + r + 1] == 0.0);
  }
}

TEST_CASE("drop envelope: a need alone eases in and out, about a tenth of the jolt it replaces") {
  for (const double hz : {30.0, 120.0}) {
    CAPTURE(hz);
    const double dt = 1.0 / hz;
    const detail::DropEnvelope env(dt);
    // 8 mm for one frame (the online filter's largest), then for 0.2 s.
    for (const std::size_t frames : {std::size_t{1}, static_cast<std::size_t>(0.2 * hz)}) {
      std::vector<double> need(400, 0.0);
      for (std::size_t t = 200; t < 200 + frames; ++t) need[t] = 0.008;
      const double jolt = largest_acceleration(need, dt);
      const double eased = largest_acceleration(env.smooth(need), dt);
      MESSAGE(hz << " Hz, an 8 mm need over " << frames << " frames: " << jolt << " m/s^2 frame by frame, " << eased
                 << " eased");
      // A raised cosine 0.15 s either side peaks at h (pi / 0.15)^2 / 2 =
      // 1.75 m/s^2 for h = 8 mm; the Gaussian and the lift a little either way.
      CHECK(eased < 2.5);
      CHECK(eased * 5.0 < jolt);
    }
  }
}

TEST_CASE("drop envelope: a look-ahead shorter than the ease shortens it, and never reads past it") {
  const detail::DropEnvelope env(1.0 / 30.0, 4);
  CHECK(env.reach() <= 4);
  std::vector<double> need(50, 0.0);
  need[25] = 0.006;
  const std::vector<double> d = env.smooth(need);
  CHECK(d[25] >= 0.006 - 1e-15);
  CHECK(d[25 - 5] == 0.0);
  CHECK(d[25 + 5] == 0.0);
}

}  // namespace
}  // namespace tonus::balance
