// Closed-form cases for every pair type: distances, normals and point
// positions worked out by hand in each test's comments.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "tonus/sim/collision.hpp"

using namespace tonus::sim;

namespace {

constexpr double kTol = 1e-12;
const double kSqrt2 = std::sqrt(2.0);

Mat3 rot(const Vec3& axis, double angle) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }
Pose at(double x, double y, double z, const Mat3& r = Mat3::Identity()) { return {Vec3(x, y, z), r}; }
// Capsule axes (local z) along world x and y.
const Mat3 kAlongX = rot(Vec3::UnitY(), std::numbers::pi / 2);
const Mat3 kAlongY = rot(Vec3::UnitX(), -std::numbers::pi / 2);

// All points of a pair, checking on the way that the swapped call gives the
// same points with negated normals.
std::vector<ContactPoint> contacts(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin) {
  std::array<ContactPoint, kMaxPointsPerPair> out{};
  std::array<ContactPoint, kMaxPointsPerPair> swapped{};
  const std::size_t n = collide(a, pa, b, pb, margin, out);
  REQUIRE(collide(b, pb, a, pa, margin, swapped) == n);
  for (std::size_t i = 0; i < n; ++i) {
    CHECK(swapped[i].pos == out[i].pos);
    CHECK(swapped[i].normal == -out[i].normal);
    CHECK(swapped[i].dist_m == out[i].dist_m);
  }
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

bool near(const Vec3& u, const Vec3& v, double tol = kTol) { return (u - v).norm() <= tol; }

void check_point(const ContactPoint& p, const Vec3& pos, const Vec3& normal, double dist) {
  CHECK(near(p.pos, pos));
  CHECK(near(p.normal, normal));
  CHECK(std::abs(p.dist_m - dist) <= kTol);
}

// True when some point is at pos (order-free checks of manifolds).
bool has_point(const std::vector<ContactPoint>& pts, const Vec3& pos, double tol = kTol) {
  for (const ContactPoint& p : pts) {
    if (near(p.pos, pos, tol)) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("collision: sphere-sphere") {
  const Shape a = Shape::sphere(0.1);
  const Shape b = Shape::sphere(0.15);
  // Centres 0.3 apart along x: gap 0.3 - 0.25; surfaces at x = 0.15 (b) and 0.2 (a).
  auto pts = contacts(a, at(0.3, 0, 0), b, at(0, 0, 0), 0.1);
  REQUIRE(pts.size() == 1);
  check_point(pts[0], {0.175, 0, 0}, {1, 0, 0}, 0.05);
  CHECK(contacts(a, at(0.3, 0, 0), b, at(0, 0, 0), 0.04).empty());  // beyond the margin
  // 0.05 of overlap: surfaces at x = 0.15 (b) and 0.1 (a).
  pts = contacts(a, at(0.2, 0, 0), b, at(0, 0, 0), 0.0);
  REQUIRE(pts.size() == 1);
  check_point(pts[0], {0.125, 0, 0}, {1, 0, 0}, -0.05);
  // Concentric: depth is the sum of the radii, along some unit direction.
  pts = contacts(a, at(1, 2, 3), b, at(1, 2, 3), 0.0);
  REQUIRE(pts.size() == 1);
  CHECK(pts[0].dist_m == doctest::Approx(-0.25));
  CHECK(pts[0].normal.norm() == doctest::Approx(1.0));
}

TEST_CASE("collision: sphere-capsule") {
  const Shape s = Shape::sphere(0.1);
  const Shape c = Shape::capsule(0.05, 0.2);  // core from x = -0.2 to 0.2
  // Over the core at x = 0.1: gap 0.3 - 0.15, surfaces at z = 0.05 and 0.2.
  auto pts = contacts(s, at(0.1, 0, 0.3), c, at(0, 0, 0, kAlongX), 0.2);
  REQUIRE(pts.size() == 1);
  check_point(pts[0], {0.1, 0, 0.125}, {0, 0, 1}, 0.15);
  // Beyond the end (0.2, 0, 0): offset (0.3, 0, 0.4), length 0.5, gap 0.35.
  pts = contacts(s, at(0.5, 0, 0.4), c, at(0, 0, 0, kAlongX), 0.4);
  REQUIRE(pts.size() == 1);
  const Vec3 n(0.6, 0, 0.8);
  check_point(pts[0], Vec3(0.2, 0, 0) + n * (0.05 + 0.175), n, 0.35);
  // Centre on the core: depth 0.15, normal perpendicular to the axis.
  pts = contacts(s, at(0.1, 0, 0), c, at(0, 0, 0, kAlongX), 0.0);
  REQUIRE(pts.size() == 1);
  CHECK(pts[0].dist_m == doctest::Approx(-0.15));
  CHECK(std::abs(pts[0].normal.x()) < kTol);
}

TEST_CASE("collision: capsule-capsule") {
  const Shape c = Shape::capsule(0.05, 0.2);
  SUBCASE("crossing at right angles") {
    // a along x at z = 0.3, b along y at the origin: gap 0.3 - 0.1.
    const auto pts = contacts(c, at(0, 0, 0.3, kAlongX), c, at(0, 0, 0, kAlongY), 0.3);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0, 0, 0.15}, {0, 0, 1}, 0.2);
  }
  SUBCASE("cores crossing: separate along the common normal") {
    const auto pts = contacts(c, at(0, 0, 0, kAlongX), c, at(0, 0, 0, kAlongY), 0.0);
    REQUIRE(pts.size() == 1);
    CHECK(pts[0].dist_m == doctest::Approx(-0.1));
    CHECK(std::abs(pts[0].normal.z()) == doctest::Approx(1.0));
  }
  SUBCASE("parallel and overlapping: both ends of the overlap") {
    // a: x in [-0.1, 0.3] at z = 0.12; b: x in [-0.3, 0.3]. Overlap [-0.1, 0.3];
    // surfaces at z = 0.05 and 0.07, gap 0.02.
    const Shape longer = Shape::capsule(0.05, 0.3);
    const auto pts = contacts(c, at(0.1, 0, 0.12, kAlongX), longer, at(0, 0, 0, kAlongX), 0.05);
    REQUIRE(pts.size() == 2);
    for (const ContactPoint& p : pts) {
      CHECK(p.dist_m == doctest::Approx(0.02));
      CHECK(near(p.normal, {0, 0, 1}));
    }
    CHECK(has_point(pts, {-0.1, 0, 0.06}));
    CHECK(has_point(pts, {0.3, 0, 0.06}));
  }
  SUBCASE("collinear, end to end") {
    // Cores [0.3, 0.7] and [-0.2, 0.2]: 0.1 apart, gap 0.
    const auto pts = contacts(c, at(0.5, 0, 0, kAlongX), c, at(0, 0, 0, kAlongX), 0.01);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0.25, 0, 0}, {1, 0, 0}, 0.0);
  }
}

TEST_CASE("collision: sphere-box") {
  const Shape box = Shape::box({0.2, 0.1, 0.05});
  const Shape s = Shape::sphere(0.05);
  SUBCASE("face") {
    const auto pts = contacts(s, at(0, 0, 0.15), box, at(0, 0, 0), 0.1);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0, 0, 0.075}, {0, 0, 1}, 0.05);
  }
  SUBCASE("edge: closest point (0.2, 0, 0.05)") {
    const auto pts = contacts(s, at(0.3, 0, 0.15), box, at(0, 0, 0), 0.2);
    REQUIRE(pts.size() == 1);
    const Vec3 n = Vec3(1, 0, 1) / kSqrt2;
    const double gap = 0.1 * kSqrt2 - 0.05;
    check_point(pts[0], Vec3(0.2, 0, 0.05) + n * gap / 2, n, gap);
  }
  SUBCASE("corner: closest point (0.2, 0.1, 0.05)") {
    const auto pts = contacts(s, at(0.3, 0.2, 0.15), box, at(0, 0, 0), 0.2);
    REQUIRE(pts.size() == 1);
    const Vec3 n = Vec3(1, 1, 1) / std::sqrt(3.0);
    const double gap = 0.1 * std::sqrt(3.0) - 0.05;
    check_point(pts[0], Vec3(0.2, 0.1, 0.05) + n * gap / 2, n, gap);
  }
  SUBCASE("centre inside: out through the nearest face") {
    // (0.17, 0, 0.01): 0.03 from +x, 0.04 from +z, 0.1 from +y. Depth 0.03 + r.
    const auto pts = contacts(s, at(0.17, 0, 0.01), box, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0.16, 0, 0.01}, {1, 0, 0}, -0.08);
  }
  SUBCASE("rotated and moved box") {
    const Pose pb = at(1, -2, 0.5, rot({1, 2, 3}, 0.7));
    const Vec3 local(0.3, 0, 0);  // 0.1 beyond the +x face
    const auto pts = contacts(s, Pose{pb.apply(local), Mat3::Identity()}, box, pb, 0.1);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], pb.apply({0.225, 0, 0}), pb.rot.col(0), 0.05);
  }
}

TEST_CASE("collision: shapes on a plane") {
  // A plane through (0.1, 0.2, 0.3) tilted 30 degrees about x: normal (0, -1/2, sqrt(3)/2).
  const Pose plane = at(0.1, 0.2, 0.3, rot(Vec3::UnitX(), std::numbers::pi / 6));
  const Vec3 n = plane.rot.col(2);
  const Vec3 t = plane.rot.col(0);
  SUBCASE("sphere") {
    const Vec3 centre = plane.pos + 0.25 * n + 0.3 * t;
    const auto pts = contacts(Shape::sphere(0.1), Pose{centre, Mat3::Identity()}, Shape::plane(), plane, 0.2);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], centre - 0.175 * n, n, 0.15);
    // Deep below the plane (a half-space): depth is height + radius.
    const auto deep =
        contacts(Shape::sphere(0.1), Pose{plane.pos - 0.5 * n, Mat3::Identity()}, Shape::plane(), plane, 0.0);
    REQUIRE(deep.size() == 1);
    CHECK(deep[0].dist_m == doctest::Approx(-0.6));
  }
  SUBCASE("plane-plane has no points") {
    std::array<ContactPoint, 4> out{};
    CHECK(collide(Shape::plane(), plane, Shape::plane(), Pose{}, 1.0, out) == 0);
  }
}

TEST_CASE("collision: capsule-plane") {
  const Shape c = Shape::capsule(0.05, 0.2);
  const Pose ground;
  SUBCASE("lying flat: both ends") {
    // Core at height 0.04, radius 0.05: 0.01 into the ground at x = +-0.2.
    const auto pts = contacts(c, at(0, 0, 0.04, kAlongX), Shape::plane(), ground, 0.0);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, {-0.2, 0, -0.005}));
    CHECK(has_point(pts, {0.2, 0, -0.005}));
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(-0.01));
  }
  SUBCASE("tilted 30 degrees: the lower end, the upper one only within the margin") {
    // Axis (cos 30, 0, sin 30), centre at 0.3: ends at heights 0.2 and 0.4.
    const Pose p = at(0, 0, 0.3, rot(Vec3::UnitY(), std::numbers::pi / 3));
    const double x_low = -0.2 * std::cos(std::numbers::pi / 6);
    auto pts = contacts(c, p, Shape::plane(), ground, 0.2);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {x_low, 0, 0.075}, {0, 0, 1}, 0.15);
    pts = contacts(c, p, Shape::plane(), ground, 0.4);
    REQUIRE(pts.size() == 2);
    check_point(pts[0], {x_low, 0, 0.075}, {0, 0, 1}, 0.15);  // deepest first
    check_point(pts[1], {-x_low, 0, 0.175}, {0, 0, 1}, 0.35);
  }
}

TEST_CASE("collision: box-plane") {
  const Shape box = Shape::box({0.1, 0.05, 0.02});
  const Pose ground;
  SUBCASE("lying flat: the four bottom corners") {
    const auto pts = contacts(box, at(0, 0, 0.015), Shape::plane(), ground, 0.0);
    REQUIRE(pts.size() == 4);
    for (const double x : {-0.1, 0.1}) {
      for (const double y : {-0.05, 0.05}) CHECK(has_point(pts, {x, y, -0.0025}));
    }
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(-0.005));
  }
  SUBCASE("margin above the top face: still the four bottom corners") {
    const auto pts = contacts(box, at(0, 0, 0.03), Shape::plane(), ground, 0.1);
    REQUIRE(pts.size() == 4);
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(0.01));
  }
  SUBCASE("tilted 10 degrees about x") {
    // Corner height: zc + y sin(th) + z cos(th). Lowest edge (y, z) = (-0.05, -0.02);
    // next (0.05, -0.02), 2 * 0.05 sin(th) higher.
    const double th = 10.0 * std::numbers::pi / 180.0;
    const double low = -0.05 * std::sin(th) - 0.02 * std::cos(th);
    const double zc = -low - 0.001;
    const Pose p = at(0, 0, zc, rot(Vec3::UnitX(), th));
    auto pts = contacts(box, p, Shape::plane(), ground, 0.01);
    REQUIRE(pts.size() == 2);
    for (const ContactPoint& q : pts) CHECK(q.dist_m == doctest::Approx(-0.001));
    pts = contacts(box, p, Shape::plane(), ground, 0.02);
    REQUIRE(pts.size() == 4);
    CHECK(pts[3].dist_m == doctest::Approx(-0.001 + 0.1 * std::sin(th)));
  }
}

TEST_CASE("collision: capsule-box") {
  const Shape box = Shape::box({0.3, 0.2, 0.1});
  SUBCASE("lying on the top face: both ends") {
    const Shape c = Shape::capsule(0.05, 0.15);
    const auto pts = contacts(c, at(0, 0, 0.148, kAlongX), box, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, {-0.15, 0, 0.099}));
    CHECK(has_point(pts, {0.15, 0, 0.099}));
    for (const ContactPoint& p : pts) {
      CHECK(p.dist_m == doctest::Approx(-0.002));
      CHECK(near(p.normal, {0, 0, 1}));
    }
  }
  SUBCASE("half over the edge: the segment clipped to the face") {
    // Core x in [0.15, 0.45], face up to x = 0.3.
    const Shape c = Shape::capsule(0.05, 0.15);
    const auto pts = contacts(c, at(0.3, 0, 0.16, kAlongX), box, at(0, 0, 0), 0.02);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, {0.15, 0, 0.105}));
    CHECK(has_point(pts, {0.3, 0, 0.105}));
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(0.01));
  }
  SUBCASE("standing on the face: one point") {
    const Shape c = Shape::capsule(0.05, 0.15);
    const auto pts = contacts(c, at(0.1, -0.05, 0.1 + 0.15 + 0.05 + 0.01), box, at(0, 0, 0), 0.02);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0.1, -0.05, 0.105}, {0, 0, 1}, 0.01);
  }
  SUBCASE("across an edge: one point on the edge") {
    // Axis (1, 0, -1)/sqrt2 through (0.4, 0, 0.2): every core point is beyond
    // the edge x = 0.3, z = 0.1; squared distance 0.02 + t^2, least at t = 0.
    const Shape c = Shape::capsule(0.02, 0.1);
    const auto pts = contacts(c, at(0.4, 0, 0.2, rot(Vec3::UnitY(), 3 * std::numbers::pi / 4)), box, at(0, 0, 0), 0.2);
    REQUIRE(pts.size() == 1);
    const Vec3 n = Vec3(1, 0, 1) / kSqrt2;
    const double gap = std::sqrt(0.02) - 0.02;
    check_point(pts[0], Vec3(0.3, 0, 0.1) + n * gap / 2, n, gap);
  }
  SUBCASE("alongside an edge: both ends of the overlap") {
    const Shape c = Shape::capsule(0.02, 0.15);
    const Vec3 n = Vec3(1, 0, 1) / kSqrt2;
    const double gap = std::sqrt(0.02) - 0.02;
    auto pts = contacts(c, at(0.4, 0, 0.2, kAlongY), box, at(0, 0, 0), 0.2);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, Vec3(0.3, -0.15, 0.1) + n * gap / 2));
    CHECK(has_point(pts, Vec3(0.3, 0.15, 0.1) + n * gap / 2));
    // Longer than the edge: the overlap ends at the box's corners.
    pts = contacts(Shape::capsule(0.02, 0.3), at(0.4, 0, 0.2, kAlongY), box, at(0, 0, 0), 0.2);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, Vec3(0.3, -0.2, 0.1) + n * gap / 2));
    CHECK(has_point(pts, Vec3(0.3, 0.2, 0.1) + n * gap / 2));
  }
  SUBCASE("core inside the box: out through the least-penetration face") {
    // Core along x at z = 0.06: 0.04 below the top face, far from the others.
    const Shape c = Shape::capsule(0.02, 0.1);
    const auto pts = contacts(c, at(0, 0, 0.06, kAlongX), box, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, {-0.1, 0, 0.07}));
    CHECK(has_point(pts, {0.1, 0, 0.07}));
    for (const ContactPoint& p : pts) {
      CHECK(p.dist_m == doctest::Approx(-0.06));
      CHECK(near(p.normal, {0, 0, 1}));
    }
  }
}

TEST_CASE("collision: box-box") {
  const Shape palm = Shape::box({0.05, 0.04, 0.01});  // top face at z = 0.01
  const Shape cube = Shape::box({0.03, 0.03, 0.03});
  SUBCASE("cube resting on the palm: its four bottom corners") {
    const auto pts = contacts(cube, at(0, 0, 0.01 + 0.03 - 0.001), palm, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 4);
    for (const double x : {-0.03, 0.03}) {
      for (const double y : {-0.03, 0.03}) CHECK(has_point(pts, {x, y, 0.0095}));
    }
    for (const ContactPoint& p : pts) {
      CHECK(p.dist_m == doctest::Approx(-0.001));
      CHECK(near(p.normal, {0, 0, 1}));
    }
  }
  SUBCASE("cube overhanging the palm's edge: clipped at the edge") {
    // Cube x in [0.01, 0.07], palm up to 0.05.
    const auto pts = contacts(cube, at(0.04, 0, 0.039), palm, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 4);
    for (const double x : {0.01, 0.05}) {
      for (const double y : {-0.03, 0.03}) CHECK(has_point(pts, {x, y, 0.0095}));
    }
  }
  SUBCASE("speculative: 5 mm above") {
    auto pts = contacts(cube, at(0, 0, 0.045), palm, at(0, 0, 0), 0.01);
    REQUIRE(pts.size() == 4);
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(0.005));
    CHECK(contacts(cube, at(0, 0, 0.045), palm, at(0, 0, 0), 0.004).empty());
  }
  SUBCASE("turned 45 degrees over a smaller plate: the octagon reduced to 4 points") {
    // Diamond |x| + |y| <= 0.05 sqrt2 clipped by the square |x|, |y| <= 0.045.
    const Shape big = Shape::box({0.05, 0.05, 0.05});
    const Shape plate = Shape::box({0.045, 0.045, 0.01});
    const auto pts = contacts(big, at(0, 0, 0.059, rot(Vec3::UnitZ(), std::numbers::pi / 4)), plate, at(0, 0, 0), 0.0);
    REQUIRE(pts.size() == 4);
    const double diamond = 0.05 * kSqrt2;
    for (const ContactPoint& p : pts) {
      CHECK(p.dist_m == doctest::Approx(-0.001));
      // An octagon vertex: on the square's side and on the diamond's.
      CHECK(std::max(std::abs(p.pos.x()), std::abs(p.pos.y())) == doctest::Approx(0.045));
      CHECK(std::abs(p.pos.x()) + std::abs(p.pos.y()) == doctest::Approx(diamond));
    }
    // The four spread over the octagon: area of their hull against the octagon's.
    const double leg = 2 * 0.045 - diamond;
    const double octagon = 0.09 * 0.09 - 2 * leg * leg;
    std::array<Vec3, 4> q{};
    for (std::size_t i = 0; i < 4; ++i) q[i] = pts[i].pos;
    std::sort(q.begin(), q.end(),
              [](const Vec3& u, const Vec3& v) { return std::atan2(u.y(), u.x()) < std::atan2(v.y(), v.x()); });
    double area = 0.0;
    for (std::size_t i = 0; i < 4; ++i) area += 0.5 * (q[i].x() * q[(i + 1) % 4].y() - q[(i + 1) % 4].x() * q[i].y());
    CHECK(area > 0.6 * octagon);
  }
  SUBCASE("edge across edge") {
    // a's lowest edge (along x) at z = za - 0.05 sqrt2; b's highest edge (along y)
    // at z = 0.05 sqrt2; they cross over the origin.
    const Shape a = Shape::box({0.1, 0.05, 0.05});
    const Shape b = Shape::box({0.05, 0.1, 0.05});
    const Pose pb = at(0, 0, 0, rot(Vec3::UnitY(), std::numbers::pi / 4));
    const double top = 0.05 * kSqrt2;
    for (const double gap : {0.01, -0.005}) {
      CAPTURE(gap);
      const auto pts = contacts(a, at(0, 0, 2 * top + gap, rot(Vec3::UnitX(), std::numbers::pi / 4)), b, pb, 0.02);
      REQUIRE(pts.size() == 1);
      check_point(pts[0], {0, 0, top + gap / 2}, {0, 0, 1}, gap);
    }
  }
  SUBCASE("corner to corner, apart: the exact Euclidean distance") {
    // Corners (0.1, 0.1, 0.1) and (0.11, 0.12, 0.13): 0.01 sqrt14 apart. The best
    // separating axis only says 0.03, so a margin of 0.035 must report nothing.
    const Shape c = Shape::box({0.1, 0.1, 0.1});
    const auto pts = contacts(c, at(0.21, 0.22, 0.23), c, at(0, 0, 0), 0.05);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0.105, 0.11, 0.115}, Vec3(1, 2, 3) / std::sqrt(14.0), 0.01 * std::sqrt(14.0));
    CHECK(contacts(c, at(0.21, 0.22, 0.23), c, at(0, 0, 0), 0.035).empty());
  }
  SUBCASE("parallel edges alongside: both ends of the overlap; just past each other: the corners") {
    // Vertical edges at (0.1, 0.1) and (0.11, 0.11): 0.01 sqrt2 apart.
    const Shape c = Shape::box({0.1, 0.1, 0.1});
    const Vec3 n = Vec3(1, 1, 0) / kSqrt2;
    auto pts = contacts(c, at(0.21, 0.21, 0.05), c, at(0, 0, 0), 0.02);  // overlap z in [-0.05, 0.1]
    REQUIRE(pts.size() == 2);
    CHECK(has_point(pts, {0.105, 0.105, -0.05}));
    CHECK(has_point(pts, {0.105, 0.105, 0.1}));
    for (const ContactPoint& p : pts) check_point(p, p.pos, n, 0.01 * kSqrt2);
    // 1e-4 past the end: corner to corner, the gap direction barely tilted.
    pts = contacts(c, at(0.21, 0.21, 0.2001), c, at(0, 0, 0), 0.02);
    REQUIRE(pts.size() == 1);
    const Vec3 gap(0.01, 0.01, 0.0001);
    check_point(pts[0], Vec3(0.105, 0.105, 0.10005), gap.normalized(), gap.norm());
  }
  SUBCASE("faces overlapping at a corner, apart: the overlap square") {
    const Shape c = Shape::box({0.1, 0.1, 0.1});
    const auto pts = contacts(c, at(0.15, 0.15, 0.205), c, at(0, 0, 0), 0.01);
    REQUIRE(pts.size() == 4);
    for (const double x : {0.05, 0.1}) {
      for (const double y : {0.05, 0.1}) CHECK(has_point(pts, {x, y, 0.1025}));
    }
    for (const ContactPoint& p : pts) CHECK(p.dist_m == doctest::Approx(0.005));
  }
  SUBCASE("corner down onto the palm: one point") {
    const Mat3 r = quat_from_two_vectors(Vec3(1, 1, 1), Vec3(0, 0, -1)).toRotationMatrix();
    const auto pts = contacts(cube, at(0, 0, 0.01 + 0.03 * std::sqrt(3.0) + 0.002, r), palm, at(0, 0, 0), 0.005);
    REQUIRE(pts.size() == 1);
    check_point(pts[0], {0, 0, 0.011}, {0, 0, 1}, 0.002);
  }
}
