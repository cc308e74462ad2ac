// Closest-point primitives (see closest.hpp).
#include "closest.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tonus::sim::narrow {
namespace {

// Below this sin^2 of their angle two segments are treated as parallel: the
// line-line parameter would be dominated by rounding (its relative error is
// about 1e-16 / sin^2), and the end-point candidates are exact for parallel
// segments and within length * angle of exact for nearly parallel ones.
constexpr double kParallelSin2 = 1e-12;

using Edge = std::array<Vec3, 2>;
using Edges = std::array<Edge, 12>;

// The 12 edges of a box centred at the origin: 4 along each axis.
Edges box_edges(const Vec3& half) {
  Edges edges{};
  std::size_t n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int k = (i + 2) % 3;
    for (const double sj : {-1.0, 1.0}) {
      for (const double sk : {-1.0, 1.0}) {
        Vec3 p = Vec3::Zero();
        p[j] = sj * half[j];
        p[k] = sk * half[k];
        p[i] = -half[i];
        edges[n][0] = p;
        p[i] = half[i];
        edges[n][1] = p;
        ++n;
      }
    }
  }
  return edges;
}

Vec3 corner(const Vec3& half, int index) {
  return {(index & 1) != 0 ? half.x() : -half.x(), (index & 2) != 0 ? half.y() : -half.y(),
          (index & 4) != 0 ? half.z() : -half.z()};
}

void keep_closer(const ClosestPair& candidate, ClosestPair& best, double& best_d2) {
  const double d2 = candidate.dist2();
  if (d2 < best_d2) {
    best = candidate;
    best_d2 = d2;
  }
}

}  // namespace

Vec3 closest_on_segment(const Vec3& p0, const Vec3& p1, const Vec3& x) {
  const Vec3 d = p1 - p0;
  const double len2 = d.squaredNorm();
  if (len2 <= 0.0) return p0;
  const double t = std::clamp(d.dot(x - p0) / len2, 0.0, 1.0);
  return p0 + t * d;
}

ClosestPair closest_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0;
  const Vec3 d2 = q1 - q0;
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  if (a <= 0.0) return {p0, closest_on_segment(q0, q1, p0)};
  if (e <= 0.0) return {closest_on_segment(p0, p1, q0), q0};

  const double b = d1.dot(d2);
  const double denom = a * e - b * b;  // a e sin^2(angle), >= 0 up to rounding
  if (denom <= kParallelSin2 * a * e) {
    // Parallel: some closest pair has an end point of one segment in it.
    ClosestPair best{p0, closest_on_segment(q0, q1, p0)};
    double best_d2 = best.dist2();
    keep_closer({p1, closest_on_segment(q0, q1, p1)}, best, best_d2);
    keep_closer({closest_on_segment(p0, p1, q0), q0}, best, best_d2);
    keep_closer({closest_on_segment(p0, p1, q1), q1}, best, best_d2);
    return best;
  }

  // Minimise |p0 + s d1 - q0 - t d2|^2: the unconstrained s of the two lines,
  // clamped; then t for that s, and if t had to be clamped, s again for it.
  // The distance is convex in (s, t), so this lands on the constrained minimum.
  const Vec3 r = p0 - q0;
  const double c = d1.dot(r);
  const double f = d2.dot(r);
  double s = std::clamp((b * f - c * e) / denom, 0.0, 1.0);
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {p0 + s * d1, q0 + t * d2};
}

bool clip_segment_to_slab(const Vec3& p0, const Vec3& p1, int axis, double limit, double& t0, double& t1) {
  const double x0 = p0[axis];
  const double dx = p1[axis] - x0;
  if (dx == 0.0) return std::abs(x0) <= limit && t0 <= t1;
  double ta = (-limit - x0) / dx;
  double tb = (limit - x0) / dx;
  if (ta > tb) std::swap(ta, tb);
  t0 = std::max(t0, ta);
  t1 = std::min(t1, tb);
  return t0 <= t1;
}

bool segment_hits_box(const Vec3& p0, const Vec3& p1, const Vec3& half) {
  double t0 = 0.0;
  double t1 = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (!clip_segment_to_slab(p0, p1, axis, half[axis], t0, t1)) return false;
  }
  return true;
}

ClosestPair closest_segment_box(const Vec3& p0, const Vec3& p1, const Vec3& half) {
  // End points first: on ties (a segment parallel to a face) an end point over
  // the face wins, which is the pair the face manifold then starts from.
  ClosestPair best{p0, clamp_to_box(p0, half)};
  double best_d2 = best.dist2();
  keep_closer({p1, clamp_to_box(p1, half)}, best, best_d2);
  for (const Edge& edge : box_edges(half)) keep_closer(closest_segments(p0, p1, edge[0], edge[1]), best, best_d2);
  return best;
}

ClosestPair closest_box_box(const Vec3& half_a, const Mat3& rot_b, const Vec3& pos_b, const Vec3& half_b) {
  const auto to_a = [&](const Vec3& local_b) -> Vec3 { return rot_b * local_b + pos_b; };
  const auto to_b = [&](const Vec3& local_a) -> Vec3 { return rot_b.transpose() * (local_a - pos_b); };

  ClosestPair best;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i) {
    const Vec3 cb = to_a(corner(half_b, i));
    keep_closer({clamp_to_box(cb, half_a), cb}, best, best_d2);
    const Vec3 ca = corner(half_a, i);
    keep_closer({ca, to_a(clamp_to_box(to_b(ca), half_b))}, best, best_d2);
  }

  // Edge pairs, skipping those whose bounding spheres are already farther
  // apart than the best pair so far.
  const Edges edges_a = box_edges(half_a);
  Edges edges_b = box_edges(half_b);
  for (Edge& e : edges_b) e = {to_a(e[0]), to_a(e[1])};
  for (const Edge& ea : edges_a) {
    const Vec3 mid_a = 0.5 * (ea[0] + ea[1]);
    const double rad_a = 0.5 * (ea[1] - ea[0]).norm();
    for (const Edge& eb : edges_b) {
      const Vec3 mid_b = 0.5 * (eb[0] + eb[1]);
      const double rad_b = 0.5 * (eb[1] - eb[0]).norm();
      const double lower = (mid_a - mid_b).norm() - rad_a - rad_b;
      if (lower > 0.0 && lower * lower >= best_d2) continue;
      keep_closer(closest_segments(ea[0], ea[1], eb[0], eb[1]), best, best_d2);
    }
  }
  return best;
}

}  // namespace tonus::sim::narrow
