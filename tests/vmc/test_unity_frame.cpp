// The frame conversion against what it claims: points map by the matrix M
// (internal forward/left/up -> Unity z/-x/y), rotations by conjugation
// R_u = M R M^-1, checked on rotation matrices and on random vectors, both
// directions; and hand-computed values from the axis map.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "tonus/host/vmc/unity_frame.hpp"

using namespace tonus;
using sim::Mat3;
using sim::Quat;
using sim::Vec3;

namespace {

Quat random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

Vec3 random_vec(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  return {u(rng), u(rng), u(rng)};
}

}  // namespace

TEST_CASE("vmc unity frame: M is the axis map, a reflection") {
  const Mat3 m = vmc::unity_from_internal_matrix();
  CHECK(m.determinant() == doctest::Approx(-1.0));
  CHECK((m * m.transpose() - Mat3::Identity()).norm() < 1e-15);
  // The humanoid faces +X, its left is +Y, up is +Z; a Unity avatar faces +Z, its right is +X, up is +Y.
  CHECK((m * Vec3::UnitX() - Vec3(0, 0, 1)).norm() < 1e-15);   // forward
  CHECK((m * Vec3::UnitY() - Vec3(-1, 0, 0)).norm() < 1e-15);  // left = -right
  CHECK((m * Vec3::UnitZ() - Vec3(0, 1, 0)).norm() < 1e-15);   // up
}

TEST_CASE("vmc unity frame: points and rotations against the matrices, both directions") {
  const Mat3 m = vmc::unity_from_internal_matrix();
  std::mt19937 rng(17);
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 p = random_vec(rng);
    const Vec3 u = random_vec(rng);
    worst = std::max(worst, (vmc::to_unity(p) - m * p).norm());
    worst = std::max(worst, (vmc::from_unity(u) - m.transpose() * u).norm());

    const Quat q = random_quat(rng);
    const Quat qu = random_quat(rng);
    // A rotation seen in Unity's axes: R_u = M R M^-1 (M^-1 = M^T).
    const Mat3 expect_u = m * q.toRotationMatrix() * m.transpose();
    worst = std::max(worst, (vmc::to_unity(q).toRotationMatrix() - expect_u).norm());
    const Mat3 expect_i = m.transpose() * qu.toRotationMatrix() * m;
    worst = std::max(worst, (vmc::from_unity(qu).toRotationMatrix() - expect_i).norm());
    // Applied to a vector: converting then rotating = rotating then converting.
    const Vec3 v = random_vec(rng);
    worst = std::max(worst, (vmc::to_unity(q) * (m * v) - m * (q * v)).norm());
    worst = std::max(worst, (vmc::from_unity(qu) * (m.transpose() * v) - m.transpose() * (qu * v)).norm());
    // Round trips and composition (a homomorphism: parents and children convert alike).
    worst = std::max(worst, (vmc::from_unity(vmc::to_unity(q)).coeffs() - q.coeffs()).norm());
    worst = std::max(worst, (vmc::to_unity(vmc::from_unity(p)) - p).norm());
    const Quat a = random_quat(rng);
    worst = std::max(
        worst,
        ((vmc::to_unity(q) * vmc::to_unity(a)).toRotationMatrix() - vmc::to_unity(q * a).toRotationMatrix()).norm());
    CHECK(vmc::to_unity(q).norm() == doctest::Approx(1.0));
  }
  MESSAGE("largest error over 1000 random points and rotations: " << worst);
  CHECK(worst < 1e-13);
}

TEST_CASE("vmc unity frame: hand-computed values") {
  // The hips 0.95 m up: Unity (0, 0.95, 0).
  CHECK((vmc::to_unity(Vec3(0, 0, 0.95)) - Vec3(0, 0.95, 0)).norm() < 1e-15);
  // A point 0.2 m to the humanoid's left and 0.1 m ahead: Unity x = -0.2 (its right is +x), z = 0.1.
  CHECK((vmc::to_unity(Vec3(0.1, 0.2, 0.0)) - Vec3(-0.2, 0.0, 0.1)).norm() < 1e-15);

  // The left upper arm raised 90 degrees about the internal +X (forward) axis:
  // q = (w, x, y, z) = (cos 45, sin 45, 0, 0); it takes the arm's rest direction
  // +Y (left) to +Z (up). By hand: (w, v) -> (w, -M v); M (1, 0, 0) = (0, 0, 1),
  // so Unity (x, y, z, w) = (0, 0, -0.70711, 0.70711): -90 degrees about Unity's
  // +Z (forward). Check: R_z(-90) = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]] takes the
  // Unity left arm's rest direction (-1, 0, 0) to (0, 1, 0): up.
  const double h = std::sqrt(0.5);
  const Quat raised(h, h, 0.0, 0.0);
  CHECK((raised * Vec3::UnitY() - Vec3::UnitZ()).norm() < 1e-15);
  const Quat u = vmc::to_unity(raised);
  CHECK(u.x() == doctest::Approx(0.0));
  CHECK(u.y() == doctest::Approx(0.0));
  CHECK(u.z() == doctest::Approx(-h));
  CHECK(u.w() == doctest::Approx(h));
  CHECK((u * Vec3(-1, 0, 0) - Vec3(0, 1, 0)).norm() < 1e-15);

  // A 90-degree turn to the left about up (internal +Z): forward +X to left +Y.
  // Unity: M (0, 0, 1) = (0, 1, 0), axis -(0, 1, 0): -90 degrees about Unity +Y,
  // which takes Unity forward (0, 0, 1) to (-1, 0, 0): the avatar's left.
  const Quat turn_left(h, 0.0, 0.0, h);
  const Quat ut = vmc::to_unity(turn_left);
  CHECK(ut.y() == doctest::Approx(-h));
  CHECK((ut * Vec3(0, 0, 1) - Vec3(-1, 0, 0)).norm() < 1e-15);
}
