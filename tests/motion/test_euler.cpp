// Euler angles: against rotation matrices written out by hand, round trips
// for random rotations in all six orders (gimbal lock included), and the
// choice of the angles nearest a reference.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "tonus/host/motion/euler.hpp"

using namespace tonus::motion;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr double kPi = std::numbers::pi;

// The six orders with their axes spelled out independently of axes().
const std::vector<std::pair<EulerOrder, std::array<Axis, 3>>> kOrders = {
    {EulerOrder::xyz, {Axis::x, Axis::y, Axis::z}}, {EulerOrder::xzy, {Axis::x, Axis::z, Axis::y}},
    {EulerOrder::yxz, {Axis::y, Axis::x, Axis::z}}, {EulerOrder::yzx, {Axis::y, Axis::z, Axis::x}},
    {EulerOrder::zxy, {Axis::z, Axis::x, Axis::y}}, {EulerOrder::zyx, {Axis::z, Axis::y, Axis::x}},
};

// Right-handed elementary rotations, written out.
Eigen::Matrix3d elementary(Axis axis, double degrees) {
  const double t = degrees * kPi / 180.0;
  const double c = std::cos(t);
  const double s = std::sin(t);
  Eigen::Matrix3d m;
  switch (axis) {
    case Axis::x: m << 1, 0, 0, 0, c, -s, 0, s, c; break;
    case Axis::y: m << c, 0, s, 0, 1, 0, -s, 0, c; break;
    case Axis::z: m << c, -s, 0, s, c, 0, 0, 0, 1; break;
  }
  return m;
}

Eigen::Matrix3d matrix_of(const std::array<Axis, 3>& a, const EulerAngles& e) {
  return elementary(a[0], e[0]) * elementary(a[1], e[1]) * elementary(a[2], e[2]);
}

Eigen::Quaterniond random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
}

void check_principal(const EulerAngles& e) {
  CHECK(e[0] > -180.0);
  CHECK(e[0] <= 180.0);
  CHECK(e[1] >= -90.0);
  CHECK(e[1] <= 90.0);
  CHECK(e[2] > -180.0);
  CHECK(e[2] <= 180.0);
}

}  // namespace

TEST_CASE("euler: orders and their axes") {
  for (const auto& [order, a] : kOrders) {
    CHECK(axes(order) == a);
    CHECK(euler_order(a[0], a[1], a[2]) == std::optional<EulerOrder>(order));
  }
  CHECK_FALSE(euler_order(Axis::x, Axis::x, Axis::y).has_value());
  CHECK_FALSE(euler_order(Axis::z, Axis::y, Axis::z).has_value());
}

TEST_CASE("euler: quaternion_from_euler is the product of the elementary rotations, first axis outermost") {
  // Closed forms: Rz(90) takes x to y; Rz(90) Rx(90) takes y to z (Rx first
  // makes it z, Rz keeps z); Rx(90) Rz(90) takes y to -x.
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  CHECK((quaternion_from_euler(EulerOrder::zyx, {90, 0, 0}) * x - y).norm() < 1e-15);
  CHECK((quaternion_from_euler(EulerOrder::zxy, {90, 90, 0}) * y - Eigen::Vector3d::UnitZ()).norm() < 1e-15);
  CHECK((quaternion_from_euler(EulerOrder::xzy, {90, 90, 0}) * y + x).norm() < 1e-15);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-400.0, 400.0);
  for (const auto& [order, a] : kOrders) {
    for (int i = 0; i < 200; ++i) {
      const EulerAngles e{angle(rng), angle(rng), angle(rng)};
      const Eigen::Matrix3d expected = matrix_of(a, e);
      CHECK((quaternion_from_euler(order, e).toRotationMatrix() - expected).norm() < 1e-14);
    }
  }
}

TEST_CASE("euler: quaternion -> angles -> quaternion for random rotations in all six orders") {
  std::mt19937 rng(5);
  for (const auto& [order, a] : kOrders) {
    double worst = 0.0;
    for (int i = 0; i < 5000; ++i) {
      const Eigen::Quaterniond q = random_rotation(rng);
      const EulerAngles e = euler_from_quaternion(q, order);
      check_principal(e);
      worst = std::max(worst, (matrix_of(a, e) - q.toRotationMatrix()).norm());
    }
    CHECK(worst < 1e-14);
  }
}

TEST_CASE("euler: principal angles come back as they went in") {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> outer(-179.9, 180.0);
  std::uniform_real_distribution<double> middle(-89.0, 89.0);
  for (const auto& [order, a] : kOrders) {
    for (int i = 0; i < 1000; ++i) {
      const EulerAngles e{outer(rng), middle(rng), outer(rng)};
      const EulerAngles back = euler_from_quaternion(quaternion_from_euler(order, e), order);
      for (std::size_t k = 0; k < 3; ++k) CHECK(back.at(k) == doctest::Approx(e.at(k)).epsilon(1e-11));
    }
  }
}

TEST_CASE("euler: at and near gimbal lock the angles still rebuild the rotation") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> outer(-180.0, 180.0);
  for (const auto& [order, a] : kOrders) {
    for (const double m : {90.0, -90.0, 90.0 - 1e-12, -90.0 + 1e-9, 90.0 - 1e-6, -90.0 + 1e-3, 89.9}) {
      for (int i = 0; i < 100; ++i) {
        const EulerAngles e{outer(rng), m, outer(rng)};
        const Eigen::Quaterniond q = quaternion_from_euler(order, e);
        const EulerAngles back = euler_from_quaternion(q, order);
        check_principal(back);
        CHECK((matrix_of(a, back) - matrix_of(a, e)).norm() < 1e-14);
        CHECK(back[1] == doctest::Approx(m).epsilon(1e-9));
      }
    }
  }
}

TEST_CASE("euler: scale and sign of the quaternion do not matter, zero gives NaN") {
  std::mt19937 rng(8);
  for (const auto& [order, a] : kOrders) {
    const Eigen::Quaterniond q = random_rotation(rng);
    const EulerAngles e = euler_from_quaternion(q, order);
    const EulerAngles scaled = euler_from_quaternion(Eigen::Quaterniond(q.coeffs() * 3.5), order);
    const EulerAngles negated = euler_from_quaternion(Eigen::Quaterniond(-q.coeffs()), order);
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(scaled.at(k) == doctest::Approx(e.at(k)).epsilon(1e-12));
      CHECK(negated.at(k) == doctest::Approx(e.at(k)).epsilon(1e-12));
    }
    const EulerAngles zero = euler_from_quaternion(Eigen::Quaterniond(0, 0, 0, 0), order);
    CHECK(std::isnan(zero[0]));
    CHECK(std::isnan(euler_from_quaternion(Eigen::Quaterniond(kNaN, 0, 0, 1), order)[1]));
  }
}

TEST_CASE("euler: the angles nearest a reference, on either branch and any number of turns away") {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> turns(-3, 3);
  for (const auto& [order, a] : kOrders) {
    for (int i = 0; i < 500; ++i) {
      const Eigen::Quaterniond q = random_rotation(rng);
      const EulerAngles p = euler_from_quaternion(q, order);
      const EulerAngles other{p[0] + 180.0, 180.0 - p[1], p[2] + 180.0};
      CHECK((matrix_of(a, other) - q.toRotationMatrix()).norm() < 1e-13);  // the second branch is the same rotation
      for (const EulerAngles& base : {p, other}) {
        const EulerAngles shifted{base[0] + 360.0 * turns(rng), base[1] + 360.0 * turns(rng),
                                  base[2] + 360.0 * turns(rng)};
        // A reference a little off the shifted angles still selects them.
        const EulerAngles reference{shifted[0] + 3.0, shifted[1] - 2.0, shifted[2] + 1.0};
        const EulerAngles near = euler_from_quaternion_near(q, order, reference);
        for (std::size_t k = 0; k < 3; ++k) CHECK(near.at(k) == doctest::Approx(shifted.at(k)).epsilon(1e-12));
      }
    }
  }
}

TEST_CASE("euler: a rotation swept through gimbal lock stays continuous with the nearest angles") {
  for (const auto& [order, a] : kOrders) {
    // Middle angle 60 -> 120 degrees: the principal angles flip at 90, the
    // nearest ones keep going.
    EulerAngles previous{30.0, 60.0, -40.0};
    double worst_step = 0.0;
    for (int step = 0; step <= 240; ++step) {
      const double m = 60.0 + 0.25 * step;
      const Eigen::Quaterniond q = quaternion_from_euler(order, {30.0, m, -40.0});
      const EulerAngles e = euler_from_quaternion_near(q, order, previous);
      CHECK((matrix_of(a, e) - q.toRotationMatrix()).norm() < 1e-13);
      for (std::size_t k = 0; k < 3; ++k) worst_step = std::max(worst_step, std::abs(e.at(k) - previous.at(k)));
      previous = e;
    }
    CHECK(worst_step < 1.0);
    CHECK(previous[0] == doctest::Approx(30.0).epsilon(1e-9));
    CHECK(previous[1] == doctest::Approx(120.0).epsilon(1e-9));
    CHECK(previous[2] == doctest::Approx(-40.0).epsilon(1e-9));
    const EulerAngles principal = euler_from_quaternion(quaternion_from_euler(order, {30.0, 120.0, -40.0}), order);
    CHECK(principal[1] == doctest::Approx(60.0).epsilon(1e-9));  // 180 - 120 on the other branch
  }
}

TEST_CASE("euler: a reference that is not finite or absurdly large is ignored") {
  const Eigen::Quaterniond q = quaternion_from_euler(EulerOrder::zyx, {10, 20, 30});
  const EulerAngles e = euler_from_quaternion_near(q, EulerOrder::zyx, {kNaN, kInf, 1e300});
  CHECK(e[0] == doctest::Approx(10.0));
  CHECK(e[1] == doctest::Approx(20.0));
  CHECK(e[2] == doctest::Approx(30.0));
}
