// What the physics core needs from the manifolds: a cube on a palm and a foot
// on the ground rest on four points that can carry their weight without
// tipping, under the small tilts, offsets, penetrations and gaps a resting
// contact goes through; capsules lying down rest on two; a fast ball sees its
// exact gap while still within the margin.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>

#include "reference.hpp"
#include "tonus/sim/collision.hpp"

using namespace tonus::sim;
using namespace tonus::sim::test;

namespace {

// Normal forces on the points that hold weight m g at the centre of mass:
// sum f = m g, sum f (p - com) x n = 0 (least-norm solution). A manifold is
// stable when these are all non-negative.
std::vector<double> support_forces(const std::vector<ContactPoint>& pts, const Vec3& com, double weight) {
  const Vec3 n = pts[0].normal;
  const Vec3 t1 = n.unitOrthogonal();
  const Vec3 t2 = n.cross(t1);
  Eigen::MatrixXd a(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Vec3 r = pts[i].pos - com;
    a.col(static_cast<Eigen::Index>(i)) << 1.0, r.dot(t1), r.dot(t2);
  }
  const Eigen::VectorXd f = a.transpose() * (a * a.transpose()).ldlt().solve(Eigen::Vector3d(weight, 0.0, 0.0));
  return {f.data(), f.data() + f.size()};
}

std::vector<ContactPoint> contacts(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double margin) {
  std::array<ContactPoint, kMaxPointsPerPair> out{};
  const std::size_t n = collide(a, pa, b, pb, margin, out);
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace

TEST_CASE("collision: 1 kg cube on a box palm: four points carrying m g without tipping") {
  const Shape cube = Shape::box({0.03, 0.03, 0.03});
  const Shape palm = Shape::box({0.045, 0.04, 0.008});
  const double mg = 1.0 * 9.81;
  const double margin = 0.002;
  Rng rng(7);
  // The palm anywhere, the cube on it with the disturbances of a resting
  // contact: +-0.5 degree tilts, +-5 mm offsets, 2 mm deep to 1 mm apart.
  for (int i = 0; i < 2000; ++i) {
    CAPTURE(i);
    const Pose pp{Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 2)), rng.rotation()};
    const double tilt = rng.uniform(-0.5, 0.5) * 3.14159265358979 / 180.0;
    const Mat3 rel = Eigen::AngleAxisd(rng.uniform(-3.2, 3.2), Vec3::UnitZ()).toRotationMatrix() *
                     Eigen::AngleAxisd(tilt, rng.unit_vector()).toRotationMatrix();
    const Vec3 offset(rng.uniform(-0.005, 0.005), rng.uniform(-0.005, 0.005),
                      0.008 + 0.03 + rng.uniform(-0.002, 0.001));
    const Pose pc{pp.apply(offset), pp.rot * rel};
    const auto pts = contacts(cube, pc, palm, pp, margin);
    REQUIRE(pts.size() == 4);
    for (const ContactPoint& p : pts) {
      CHECK(p.normal.dot(pp.rot.col(2)) > 0.9999);  // the palm's face normal
      CHECK(p.dist_m > -0.0025);                    // depth never exaggerated
    }
    const auto f = support_forces(pts, pc.pos, mg);
    double total = 0.0;
    for (const double fi : f) {
      CHECK(fi >= 0.0);  // no point pulls: the weight sits inside the manifold
      total += fi;
    }
    CHECK(total == doctest::Approx(mg));
  }
}

TEST_CASE("collision: box foot on the ground: exactly four corners when flat, four within the margin when rocking") {
  const Shape foot = Shape::box({0.12, 0.05, 0.03});
  const Pose ground;
  // Flat, sunk 0.5 mm: the four sole corners, equally deep, loaded equally.
  auto pts = contacts(foot, Pose{Vec3(0.2, -0.1, 0.0295), Mat3::Identity()}, Shape::plane(), ground, 0.02);
  REQUIRE(pts.size() == 4);
  for (const ContactPoint& p : pts) {
    CHECK(p.dist_m == doctest::Approx(-0.0005));
    CHECK(p.pos.z() == doctest::Approx(-0.00025));
  }
  for (const double f : support_forces(pts, Vec3(0.2, -0.1, 0.0295), 700.0)) CHECK(f == doctest::Approx(175.0));
  // Rocking by up to 2 degrees about any horizontal axis: the sole's corners
  // stay within a 2 cm margin, and they are the ones reported.
  Rng rng(11);
  for (int i = 0; i < 500; ++i) {
    const Vec3 axis(rng.uniform(-1, 1), rng.uniform(-1, 1), 0.0);
    const Mat3 r =
        Eigen::AngleAxisd(rng.uniform(0.0, 2.0) * 3.14159265358979 / 180.0, axis.normalized()).toRotationMatrix();
    const Pose p{Vec3(0, 0, 0.03), r};
    pts = contacts(foot, p, Shape::plane(), ground, 0.02);
    REQUIRE(pts.size() == 4);
    for (const ContactPoint& q : pts)
      CHECK(p.inverse_apply(q.pos + 0.5 * q.dist_m * q.normal).z() == doctest::Approx(-0.03));
  }
}

TEST_CASE("collision: capsules lying down rest on two points") {
  const Shape forearm = Shape::capsule(0.035, 0.12);
  const Mat3 along_x = Eigen::AngleAxisd(3.14159265358979 / 2, Vec3::UnitY()).toRotationMatrix();
  // On the ground, on a table top (box), and on another capsule, each with a
  // slight roll about its own axis and a pitch of up to 0.5 degree.
  Rng rng(3);
  for (int i = 0; i < 300; ++i) {
    const Mat3 wobble = Eigen::AngleAxisd(rng.uniform(-0.0087, 0.0087), Vec3::UnitY()).toRotationMatrix() *
                        Eigen::AngleAxisd(rng.uniform(-3.0, 3.0), Vec3::UnitX()).toRotationMatrix();
    const Pose arm{Vec3(rng.uniform(-0.1, 0.1), 0.0, 0.035 - 0.0005), wobble * along_x};
    CHECK(contacts(forearm, arm, Shape::plane(), Pose{}, 0.01).size() == 2);
    const Pose table{Vec3(0, 0, -0.02), Mat3::Identity()};
    CHECK(contacts(forearm, arm, Shape::box({0.4, 0.3, 0.02}), table, 0.01).size() == 2);
    const Pose other{Vec3(0, 0, -0.035), along_x};
    CHECK(contacts(forearm, arm, Shape::capsule(0.035, 0.3), other, 0.01).size() == 2);
  }
}

TEST_CASE("collision: a 0.1 m ball at 10 m/s: the exact gap at every 1 ms step within the margin") {
  // 1 cm per step towards a 1 cm thick palm; the speculative margin is 2 cm.
  // Every step within the margin must see the exact remaining gap, so the
  // solver can stop the ball at the surface instead of passing through.
  const Shape ball = Shape::sphere(0.05);
  const Shape palm = Shape::box({0.05, 0.04, 0.005});
  const Pose pp{Vec3(0.3, 0.1, 1.0), Eigen::AngleAxisd(0.4, Vec3(0, 1, 1).normalized()).toRotationMatrix()};
  const Vec3 up = pp.rot.col(2);
  int seen = 0;
  for (int step = 0; step < 10; ++step) {
    const double gap = 0.045 - 0.01 * step;  // of the ball's surface above the palm
    const Pose pb{pp.pos + up * (0.005 + 0.05 + gap), Mat3::Identity()};
    const auto pts = contacts(ball, pb, palm, pp, 0.02);
    if (gap > 0.02) {
      CHECK(pts.empty());
      continue;
    }
    REQUIRE(pts.size() == 1);
    CHECK(pts[0].dist_m == doctest::Approx(gap).epsilon(1e-12));
    CHECK((pts[0].normal - up).norm() < 1e-12);
    ++seen;
  }
  CHECK(seen >= 2);  // at least one step before reaching the surface saw it coming
}
