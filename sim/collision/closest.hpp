// Closest-point primitives on points, segments and boxes, shared by the pair
// routines. Boxes here are axis aligned and centred at the origin (the caller
// works in the box's frame), given by their half extents.
#pragma once

#include "tonus/sim/math.hpp"

namespace tonus::sim::narrow {

// A closest pair: `first` on the first argument, `second` on the second.
struct ClosestPair {
  Vec3 first = Vec3::Zero();
  Vec3 second = Vec3::Zero();
  [[nodiscard]] double dist2() const { return (first - second).squaredNorm(); }
};

inline double sign_of(double x) { return x < 0.0 ? -1.0 : 1.0; }

// Closest point to x on the segment [p0, p1].
Vec3 closest_on_segment(const Vec3& p0, const Vec3& p1, const Vec3& x);

// Closest points of the segments [p0, p1] and [q0, q1] (exact, including
// parallel and degenerate segments; for parallel ones, one of the pairs).
ClosestPair closest_segments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// Closest point of the solid box to a point.
inline Vec3 clamp_to_box(const Vec3& x, const Vec3& half) { return x.cwiseMax(-half).cwiseMin(half); }

// True when the segment touches the solid box.
bool segment_hits_box(const Vec3& p0, const Vec3& p1, const Vec3& half);

// Parameter interval [t0, t1] of the segment p0 + t (p1 - p0), t in [0, 1],
// inside the slab |x[axis]| <= limit; false when it is empty.
bool clip_segment_to_slab(const Vec3& p0, const Vec3& p1, int axis, double limit, double& t0, double& t1);

// Exact closest pair of a segment and a box that do not intersect: the
// minimum over the segment's end points against the box and the segment
// against the box's 12 edges (a closest pair of two convex polytopes is
// vertex-face or edge-edge). `first` is on the segment.
ClosestPair closest_segment_box(const Vec3& p0, const Vec3& p1, const Vec3& half);

// Exact closest pair of two disjoint boxes, box B given by its rotation and
// centre in A's frame: B's corners against A, A's corners against B and the
// 144 edge pairs (pruned by bounding spheres). `first` on A, `second` on B,
// both in A's frame.
ClosestPair closest_box_box(const Vec3& half_a, const Mat3& rot_b, const Vec3& pos_b, const Vec3& half_b);

}  // namespace tonus::sim::narrow
