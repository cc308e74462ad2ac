// Bad input gives no points (never NaN, never a crash), output limits are
// honoured, results scale with the scene, and collide() allocates nothing:
// operator new and the malloc family are counted while collide() runs
// (tests/support/allocation_counter).
#include <doctest/doctest.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>

#include "reference.hpp"
#include "support/allocation_counter.hpp"
#include "tonus/sim/collision.hpp"

using namespace tonus::sim;
using namespace tonus::sim::test;

namespace {

const std::array<ShapeType, 4> kTypes = {ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::plane};

// Calls collide with an output pre-filled with a sentinel, checks that
// nothing beyond the returned count was touched and no NaN came out.
std::size_t guarded(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin) {
  const ContactPoint sentinel{Vec3(7, 7, 7), Vec3(0, 1, 0), 7.0};
  std::array<ContactPoint, 6> out{};
  out.fill(sentinel);
  const std::size_t n = collide(a, pa, b, pb, margin, std::span<ContactPoint>(out).first(kMaxPointsPerPair));
  CHECK(n <= kMaxPointsPerPair);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (i < n) {
      CHECK(all_finite(out[i].pos));
      CHECK(all_finite(out[i].normal));
      CHECK(std::isfinite(out[i].dist_m));
    } else {
      CHECK(out[i].pos == sentinel.pos);
      CHECK(out[i].dist_m == sentinel.dist_m);
    }
  }
  return n;
}

}  // namespace

TEST_CASE("collision: shape validity and bounding radius") {
  CHECK(shape_is_valid(Shape::sphere(0.1)));
  CHECK(shape_is_valid(Shape::capsule(0.05, 0.2)));
  CHECK(shape_is_valid(Shape::box({0.1, 0.2, 0.3})));
  CHECK(shape_is_valid(Shape::plane()));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {0.0, -0.1, nan, inf}) {
    CAPTURE(bad);
    CHECK_FALSE(shape_is_valid(Shape::sphere(bad)));
    CHECK_FALSE(shape_is_valid(Shape::capsule(bad, 0.2)));
    CHECK_FALSE(shape_is_valid(Shape::capsule(0.05, bad)));
    CHECK_FALSE(shape_is_valid(Shape::box({0.1, bad, 0.3})));
  }
  CHECK(bounding_radius(Shape::sphere(0.1)) == 0.1);
  CHECK(bounding_radius(Shape::capsule(0.05, 0.2)) == doctest::Approx(0.25));
  CHECK(bounding_radius(Shape::box({0.1, 0.2, 0.2})) == doctest::Approx(0.3));
  CHECK(std::isinf(bounding_radius(Shape::plane())));
}

TEST_CASE("collision: bad input gives no points") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Shape ok = Shape::sphere(0.1);
  const Pose here = Pose{Vec3(0, 0, 0.05), Mat3::Identity()};
  const Pose ground;
  // Sanity: the good configuration does touch.
  REQUIRE(guarded(ok, here, Shape::plane(), ground, 0.01) == 1);

  SUBCASE("degenerate shapes, in either slot") {
    for (const Shape& bad : {Shape::sphere(0.0), Shape::sphere(-1.0), Shape::sphere(nan), Shape::capsule(0.1, 0.0),
                             Shape::capsule(inf, 0.1), Shape::box({0.1, 0.0, 0.1}), Shape::box({0.1, 0.1, nan})}) {
      CHECK(guarded(bad, here, ok, here, 1.0) == 0);
      CHECK(guarded(ok, here, bad, here, 1.0) == 0);
      CHECK(guarded(bad, here, Shape::plane(), ground, 1.0) == 0);
    }
    Shape unknown = ok;
    unknown.type = static_cast<ShapeType>(9);
    CHECK_FALSE(shape_is_valid(unknown));
    CHECK(guarded(unknown, here, ok, here, 1.0) == 0);
  }
  SUBCASE("non-finite poses") {
    for (const double bad : {nan, inf, -inf}) {
      Pose p = here;
      p.pos.y() = bad;
      CHECK(guarded(ok, p, Shape::plane(), ground, 1.0) == 0);
      CHECK(guarded(Shape::plane(), ground, ok, p, 1.0) == 0);
      Pose r = here;
      r.rot(1, 2) = bad;
      CHECK(guarded(ok, r, Shape::box({0.1, 0.1, 0.1}), here, 1.0) == 0);
    }
  }
  SUBCASE("rotations that are not rotations") {
    Mat3 reflection = Mat3::Identity();
    reflection(2, 2) = -1.0;
    Mat3 shear = Mat3::Identity();
    shear(0, 1) = 0.1;
    for (const Mat3& bad : {Mat3(2.0 * Mat3::Identity()), reflection, shear, Mat3(Mat3::Zero())}) {
      CHECK(guarded(Shape::box({0.1, 0.1, 0.1}), Pose{here.pos, bad}, Shape::plane(), ground, 1.0) == 0);
      CHECK(guarded(Shape::plane(), Pose{Vec3::Zero(), bad}, ok, here, 1.0) == 0);
    }
    // A rotation rounded to float is still a rotation.
    const Mat3 r = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix().cast<float>().cast<double>();
    CHECK(guarded(Shape::box({0.1, 0.1, 0.1}), Pose{here.pos, r}, Shape::plane(), ground, 1.0) > 0);
  }
  SUBCASE("non-finite margin") {
    CHECK(guarded(ok, here, Shape::plane(), ground, nan) == 0);
    CHECK(guarded(ok, here, Shape::plane(), ground, inf) == 0);
  }
  SUBCASE("overflowing sizes and positions never give NaN") {
    const Shape huge = Shape::box({1e300, 1e300, 1e300});
    guarded(huge, here, Shape::box({1e300, 1, 1}), Pose{Vec3(1e300, 0, 0), Mat3::Identity()}, 1.0);
    guarded(Shape::capsule(1e300, 1e300), here, Shape::plane(), ground, 1e300);
    guarded(ok, Pose{Vec3(1e308, -1e308, 1e308), Mat3::Identity()}, Shape::capsule(0.1, 0.1), here, 1.0);
  }
}

TEST_CASE("collision: the output span limits the points, the deepest always comes first") {
  // Cube on a palm: 4 points, one corner 1 mm deeper than the rest (tilted).
  const Shape cube = Shape::box({0.03, 0.03, 0.03});
  const Shape palm = Shape::box({0.05, 0.05, 0.01});
  const Pose p{Vec3(0, 0, 0.039), Eigen::AngleAxisd(0.01, Vec3(1, 1, 0).normalized()).toRotationMatrix()};
  std::array<ContactPoint, 8> big{};
  const std::size_t all = collide(cube, p, palm, Pose{}, 0.01, big);
  REQUIRE(all == kMaxPointsPerPair);  // never more than 4, even with room for 8
  for (std::size_t k = 0; k <= 3; ++k) {
    CAPTURE(k);
    std::array<ContactPoint, 4> out{};
    const std::size_t n = collide(cube, p, palm, Pose{}, 0.01, std::span<ContactPoint>(out).first(k));
    CHECK(n == k);
    if (n > 0) CHECK(out[0].dist_m == big[0].dist_m);
    for (std::size_t i = 1; i < all; ++i) CHECK(big[i].dist_m >= big[0].dist_m);
  }
}

TEST_CASE("collision: scaling the whole scene scales the gaps and keeps the normals") {
  Rng rng(4242);
  const auto scaled = [](const Shape& s, double k) {
    Shape t = s;
    t.radius_m *= k;
    t.half_length_m *= k;
    t.half_extents_m *= k;
    return t;
  };
  for (const ShapeType ta : kTypes) {
    for (const ShapeType tb : kTypes) {
      if (ta == ShapeType::plane && tb == ShapeType::plane) continue;
      for (int i = 0; i < 200; ++i) {
        const Config c = random_config(ta, tb, rng);
        std::array<ContactPoint, 4> ref{};
        const std::size_t n = collide(c.a, c.pa, c.b, c.pb, c.margin, ref);
        for (const double k : {1e-3, 1e3}) {
          CAPTURE(k);
          std::array<ContactPoint, 4> out{};
          const std::size_t m = collide(scaled(c.a, k), Pose{c.pa.pos * k, c.pa.rot}, scaled(c.b, k),
                                        Pose{c.pb.pos * k, c.pb.rot}, c.margin * k, out);
          // A point right at the margin may fall either side after rounding.
          bool borderline = false;
          for (std::size_t j = 0; j < n; ++j) borderline = borderline || std::abs(ref[j].dist_m - c.margin) < 1e-9;
          if (borderline) continue;
          REQUIRE(m == n);
          if (n > 0) CHECK(std::abs(out[0].dist_m / k - ref[0].dist_m) <= 1e-9);  // the deepest
          for (std::size_t j = 0; j < n; ++j) {
            // Points of equal depth may come in another order: match by position.
            std::size_t best = 0;
            for (std::size_t q = 1; q < m; ++q) {
              if ((out[q].pos / k - ref[j].pos).norm() < (out[best].pos / k - ref[j].pos).norm()) best = q;
            }
            CHECK((out[best].pos / k - ref[j].pos).norm() <= 1e-9);
            CHECK(std::abs(out[best].dist_m / k - ref[j].dist_m) <= 1e-9);
            CHECK((out[best].normal - ref[j].normal).norm() <= 1e-9);
          }
        }
      }
    }
  }
}

TEST_CASE("collision: collide allocates nothing") {
  Rng rng(99);
  std::array<ContactPoint, 4> out{};
  std::size_t points = 0;
  // Prove the counter counts before trusting a zero.
  REQUIRE(tonus::test::probe_allocation_counter() == 2);

  long allocations = 0;
  for (const ShapeType ta : kTypes) {
    for (const ShapeType tb : kTypes) {
      for (int i = 0; i < 500; ++i) {
        const Config c = random_config(ta, tb, rng);
        tonus::test::start_counting_allocations();
        points += collide(c.a, c.pa, c.b, c.pb, c.margin, out);
        allocations += tonus::test::stop_counting_allocations();
      }
    }
  }
  CHECK(points > 1000);
  CHECK(allocations == 0);
}
