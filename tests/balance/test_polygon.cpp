// The convex hull, checked by its defining properties (every point inside or
// on it, its vertices input points turning left), for clouds small enough to
// be taken in place and large enough to go to the heap; the in-place form
// gives the same polygon and keeps its storage.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tonus/host/balance/polygon.hpp"

namespace tonus::balance {
namespace {

double turn(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

TEST_CASE("convex hull: every point inside or on it, its vertices input points turning left, in place or not") {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 0.1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const std::size_t n : {0U, 1U, 2U, 3U, 5U, 12U, 24U, 63U, 64U, 65U, 200U}) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<Vec2> pts;
      for (std::size_t i = 0; i < n; ++i) pts.emplace_back(gauss(rng), gauss(rng));
      if (n > 4) {
        pts[1] = pts[0];                 // a repeat
        pts[2] = Vec2(nan, gauss(rng));  // a non-finite point is skipped
      }
      const ConvexPolygon hull = convex_hull(pts);
      ConvexPolygon in_place;
      in_place.vertices.reserve(kHullInlinePoints);
      const Vec2* storage = in_place.vertices.data();
      convex_hull(pts, in_place);
      CHECK(in_place.vertices == hull.vertices);
      if (hull.vertices.size() <= kHullInlinePoints) CHECK(in_place.vertices.data() == storage);
      const std::size_t v = hull.vertices.size();
      std::size_t finite = 0;
      for (const Vec2& p : pts) finite += p.allFinite() ? 1U : 0U;
      CHECK(v <= finite);
      if (finite >= 3) {
        REQUIRE(v >= 3);  // Gaussian clouds are never collinear
        for (std::size_t i = 0; i < v; ++i)
          CHECK(turn(hull.vertices[i], hull.vertices[(i + 1) % v], hull.vertices[(i + 2) % v]) > 0.0);
        for (const Vec2& p : pts) {
          if (p.allFinite()) CHECK(signed_distance(hull, p) <= 1e-12);
        }
      }
      for (const Vec2& h : hull.vertices) {
        bool found = false;
        for (const Vec2& p : pts) found = found || p == h;
        CHECK(found);
      }
    }
  }
}

}  // namespace
}  // namespace tonus::balance
