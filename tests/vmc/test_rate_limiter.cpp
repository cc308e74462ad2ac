// RateLimiter: the range, the count over a second, no burst after a stall.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "tonus/host/vmc/rate_limiter.hpp"

using tonus::vmc::RateLimiter;

TEST_CASE("vmc rate limiter: 1 to 200 Hz") {
  CHECK(RateLimiter::validate(60.0).empty());
  CHECK(RateLimiter::validate(1.0).empty());
  CHECK(RateLimiter::validate(200.0).empty());
  CHECK_FALSE(RateLimiter::validate(0.5).empty());
  CHECK_FALSE(RateLimiter::validate(201.0).empty());
  CHECK_FALSE(RateLimiter::validate(std::numeric_limits<double>::quiet_NaN()).empty());
  CHECK(RateLimiter(1000.0).hz() == 200.0);
  CHECK(RateLimiter(0.0).hz() == 1.0);
  CHECK(RateLimiter(std::numeric_limits<double>::quiet_NaN()).hz() == 60.0);
  CHECK(RateLimiter().period_us() == 16667);
}

TEST_CASE("vmc rate limiter: polled at 1 kHz for a second, 60 Hz gives 60 ticks on a steady grid") {
  RateLimiter r(60.0);
  int ticks = 0;
  std::int64_t last = -1;
  std::int64_t worst_gap = 0;
  for (std::int64_t t = 5'000'000; t < 6'000'000; t += 1000) {
    if (r.due(t)) {
      ++ticks;
      if (last >= 0) worst_gap = std::max(worst_gap, t - last);
      last = t;
    }
  }
  CHECK(ticks == 60);
  CHECK(worst_gap <= 17'000);  // the grid, quantised by the 1 ms polling
}

TEST_CASE("vmc rate limiter: a stall does not make a burst") {
  RateLimiter r(100.0);
  CHECK(r.due(0));
  CHECK_FALSE(r.due(5'000));
  CHECK(r.due(10'000));
  CHECK(r.due(500'000));        // half a second late: one tick ...
  CHECK_FALSE(r.due(500'001));  // ... not 49 to catch up
  CHECK_FALSE(r.due(509'000));
  CHECK(r.due(510'000));
  r.reset();
  CHECK(r.due(510'001));
}
