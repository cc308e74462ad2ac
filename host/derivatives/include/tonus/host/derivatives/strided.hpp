// A strided view of doubles, so one coordinate of an array of packed points
// (x0 y0 z0 x1 y1 z1 ...) is processed in place: element i is data[i * stride].
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <type_traits>

namespace tonus::derivatives {

template <class T>
struct Strided {
  T* data = nullptr;
  std::size_t size = 0;
  std::size_t stride = 1;

  Strided() = default;
  Strided(T* d, std::size_t n, std::size_t s = 1) : data(d), size(n), stride(s) {}
  // A contiguous span (and, for const views, a mutable one).
  template <class U>
  requires std::is_convertible_v<U (*)[], T (*)[]> Strided(std::span<U> s)
      : data(s.data()), size(s.size()) {}  // NOLINT(google-explicit-constructor)

  T& operator[](std::size_t i) const { return data[i * stride]; }
  [[nodiscard]] bool empty() const { return size == 0; }
};

// Coordinate c (0, 1, 2) of a series of points; Eigen::Vector3d is three packed doubles.
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
inline Strided<const double> coordinate(std::span<const Eigen::Vector3d> points, std::size_t c) {
  if (points.empty()) return {};
  return {points.front().data() + c, points.size(), 3};
}
inline Strided<double> coordinate(std::span<Eigen::Vector3d> points, std::size_t c) {
  if (points.empty()) return {};
  return {points.front().data() + c, points.size(), 3};
}

}  // namespace tonus::derivatives
