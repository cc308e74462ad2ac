// Euler angles <-> quaternions for the six Tait-Bryan orders.
//
// Decomposition of R = R_i(a) R_j(b) R_k(c), with s = +1 for a cyclic order
// (xyz, yzx, zxy) and -1 otherwise: a = atan2(-s R_jk, R_kk); then
// M = R_i(-a) R = R_j(b) R_k(c) gives b = atan2(s M_ik, M_kk) and
// c = atan2(s M_ji, M_jj). Taking b and c from M rather than from R keeps the
// result exact near gimbal lock, where a is poorly determined on its own.
#include "tonus/host/motion/euler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace tonus::motion {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kMaxReference = 1e6;     // degrees; beyond, whole turns lose the angle's precision
constexpr double kLockTolerance = 1e-12;  // rotation-matrix error accepted for the gimbal-lock candidate

constexpr double kNoDistance = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Vector3d unit(Axis a) { return Eigen::Vector3d::Unit(static_cast<Eigen::Index>(a)); }

// The angle equal to `angle` modulo 360 closest to `reference`.
double near_turn(double angle, double reference) {
  if (!std::isfinite(reference) || std::abs(reference) > kMaxReference) return angle;
  return angle + 360.0 * std::round((reference - angle) / 360.0);
}

// Axis indices of an order and its sign: +1 for the cyclic orders.
struct Decomposition {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  Eigen::Index k = 0;
  double s = 1.0;
  Axis first_axis = Axis::x;
};

Decomposition decompose(EulerOrder order) {
  const std::array<Axis, 3> a = axes(order);
  Decomposition d;
  d.i = static_cast<Eigen::Index>(a[0]);
  d.j = static_cast<Eigen::Index>(a[1]);
  d.k = static_cast<Eigen::Index>(a[2]);
  d.s = (d.j - d.i + 3) % 3 == 1 ? 1.0 : -1.0;
  d.first_axis = a[0];
  return d;
}

// The second and third angles (radians) once the first is fixed.
std::pair<double, double> rest_given_first(const Eigen::Matrix3d& r, const Decomposition& d, double first) {
  const Eigen::Matrix3d m = Eigen::AngleAxisd(-first, unit(d.first_axis)).toRotationMatrix() * r;
  // M_kk = cos(b) >= 0 when `first` comes from R; rounding may leave it at -1e-17.
  return {std::atan2(d.s * m(d.i, d.k), std::max(m(d.k, d.k), 0.0)), std::atan2(d.s * m(d.j, d.i), m(d.j, d.j))};
}

double squared_distance(const EulerAngles& a, const EulerAngles& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double delta = std::isfinite(b.at(i)) && std::abs(b.at(i)) <= kMaxReference ? a.at(i) - b.at(i) : 0.0;
    d += delta * delta;
  }
  return d;
}

}  // namespace

std::array<Axis, 3> axes(EulerOrder order) {
  switch (order) {
    case EulerOrder::xyz: return {Axis::x, Axis::y, Axis::z};
    case EulerOrder::xzy: return {Axis::x, Axis::z, Axis::y};
    case EulerOrder::yxz: return {Axis::y, Axis::x, Axis::z};
    case EulerOrder::yzx: return {Axis::y, Axis::z, Axis::x};
    case EulerOrder::zxy: return {Axis::z, Axis::x, Axis::y};
    case EulerOrder::zyx: break;
  }
  return {Axis::z, Axis::y, Axis::x};
}

std::optional<EulerOrder> euler_order(Axis first, Axis second, Axis third) {
  for (const EulerOrder o :
       {EulerOrder::xyz, EulerOrder::xzy, EulerOrder::yxz, EulerOrder::yzx, EulerOrder::zxy, EulerOrder::zyx}) {
    const std::array<Axis, 3> a = axes(o);
    if (a[0] == first && a[1] == second && a[2] == third) return o;
  }
  return std::nullopt;
}

Eigen::Quaterniond quaternion_from_euler(EulerOrder order, const EulerAngles& degrees) {
  const std::array<Axis, 3> a = axes(order);
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (std::size_t n = 0; n < 3; ++n) q = q * Eigen::AngleAxisd(degrees.at(n) * kDegree, unit(a.at(n)));
  return q;
}

EulerAngles euler_from_quaternion(const Eigen::Quaterniond& q, EulerOrder order) {
  const double norm = q.norm();
  if (!std::isfinite(norm) || norm == 0.0) return {kNaN, kNaN, kNaN};
  const Eigen::Matrix3d r = Eigen::Quaterniond(q.coeffs() / norm).toRotationMatrix();
  const Decomposition d = decompose(order);
  const double first = std::atan2(-d.s * r(d.j, d.k), r(d.k, d.k));
  const auto [second, third] = rest_given_first(r, d, first);
  // atan2 gives [-pi, pi]; -180 becomes 180 so the range is (-180, 180], and
  // the conversion to degrees may not overshoot the bounds.
  const auto outer = [](double radians) {
    const double deg = radians / kDegree;
    return deg <= -180.0 || deg > 180.0 ? 180.0 : deg;
  };
  return {outer(first), std::clamp(second / kDegree, -90.0, 90.0), outer(third)};
}

EulerAngles euler_from_quaternion_near(const Eigen::Quaterniond& q, EulerOrder order, const EulerAngles& reference) {
  const EulerAngles p = euler_from_quaternion(q, order);
  if (std::isnan(p[0])) return p;
  std::array<EulerAngles, 3> candidates{p, EulerAngles{p[0] + 180.0, 180.0 - p[1], p[2] + 180.0}, p};
  std::size_t count = 2;
  // At gimbal lock only a +- c is fixed: keeping the reference's first angle
  // is then exact and continuous. Taken only if it rebuilds q.
  if (std::isfinite(reference[0]) && std::abs(reference[0]) <= kMaxReference) {
    const Eigen::Matrix3d r = Eigen::Quaterniond(q.coeffs() / q.norm()).toRotationMatrix();
    const auto [second, third] = rest_given_first(r, decompose(order), reference[0] * kDegree);
    const EulerAngles locked{reference[0], second / kDegree, third / kDegree};
    if ((quaternion_from_euler(order, locked).toRotationMatrix() - r).norm() < kLockTolerance) {
      candidates[count++] = locked;
    }
  }
  EulerAngles best = p;
  double best_distance = kNoDistance;
  for (std::size_t n = 0; n < count; ++n) {
    EulerAngles shifted{};
    for (std::size_t k = 0; k < 3; ++k) shifted.at(k) = near_turn(candidates.at(n).at(k), reference.at(k));
    const double d = squared_distance(shifted, reference);
    if (d < best_distance) {
      best = shifted;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace tonus::motion
