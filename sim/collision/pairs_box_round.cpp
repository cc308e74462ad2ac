// Rounded shapes against a box: sphere-box and capsule-box, both worked out in
// the box's frame.
#include <array>
#include <cmath>
#include <limits>

#include "closest.hpp"
#include "narrow.hpp"

namespace tonus::sim::narrow {
namespace {

// Adds a contact given in the box's frame.
void add_local(const Pose& box, const Vec3& on_box, const Vec3& normal, double dist, Candidates& out) {
  out.add_from_b(box.apply(on_box), box.rot * normal, dist);
}

// Points of the core segment [p0, p1] over face `axis` (outward sign `side`)
// of the box: the segment clipped to the face's prism, its two ends each
// with its height over the face. The height is linear along the segment, so
// the ends bound it. Ends below `min_height` are skipped. False when the
// segment does not pass over the face at all.
bool add_face_points(const Pose& box, const Vec3& half, const Vec3& p0, const Vec3& p1, int axis, double side,
                     double radius, double min_height, Candidates& out) {
  double t0 = 0.0;
  double t1 = 1.0;
  for (const int j : {(axis + 1) % 3, (axis + 2) % 3}) {
    if (!clip_segment_to_slab(p0, p1, j, half[j], t0, t1)) return false;
  }
  Vec3 normal = Vec3::Zero();
  normal[axis] = side;
  const double ts[2] = {t0, t1};
  const int ends = (t1 - t0) * (p1 - p0).norm() > kSameRel * out.scale() ? 2 : 1;
  for (int i = 0; i < ends; ++i) {
    const Vec3 x = p0 + ts[i] * (p1 - p0);
    const double height = side * x[axis] - half[axis];
    if (height < min_height) continue;
    Vec3 on_face = x;
    on_face[axis] = side * half[axis];
    add_local(box, on_face, normal, height - radius, out);
  }
  return true;
}

// The core segment's part alongside box edge `axis`: its parameter interval
// within the edge's slab. Returns how many ends (0, 1 or 2) it has.
int overlap_along(const Vec3& p0, const Vec3& p1, const Vec3& half, int axis, double tiny, std::array<Vec3, 2>& ends) {
  double t0 = 0.0;
  double t1 = 1.0;
  if (!clip_segment_to_slab(p0, p1, axis, half[axis], t0, t1)) return 0;
  ends = {p0 + t0 * (p1 - p0), p0 + t1 * (p1 - p0)};
  return (ends[1] - ends[0]).norm() > tiny ? 2 : 1;
}

// The face axis of the box whose normal is most aligned with n (box frame).
int dominant_axis(const Vec3& n) {
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  return k;
}

}  // namespace

void sphere_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  const Vec3& half = b.half_extents_m;
  const Vec3 c = pb.inverse_apply(pa.pos);
  const Vec3 q = clamp_to_box(c, half);
  const Vec3 d = c - q;
  const double len = d.norm();
  if (len > kTinyRel * out.scale()) {
    add_local(pb, q, d / len, len - a.radius_m, out);
    return;
  }
  // Centre inside (or on) the box: out through the nearest face, which is the
  // least penetration for any centre depth.
  int k = 0;
  (half - c.cwiseAbs()).minCoeff(&k);
  const double side = sign_of(c[k]);
  Vec3 on_face = c;
  on_face[k] = side * half[k];
  Vec3 normal = Vec3::Zero();
  normal[k] = side;
  add_local(pb, on_face, normal, side * c[k] - half[k] - a.radius_m, out);
}

void capsule_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  const Vec3& half = b.half_extents_m;
  const double r = a.radius_m;
  const double tiny = kTinyRel * out.scale();
  const Vec3 c = pb.inverse_apply(pa.pos);
  const Vec3 axis = pb.rot.transpose() * pa.rot.col(2);
  const Vec3 p0 = c - a.half_length_m * axis;
  const Vec3 p1 = c + a.half_length_m * axis;

  if (!segment_hits_box(p0, p1, half)) {
    // Apart cores: the exact closest pair, plus the face manifold when that
    // pair is (nearly) along a face normal, e.g. a capsule lying on a face.
    const ClosestPair cp = closest_segment_box(p0, p1, half);
    const Vec3 d = cp.first - cp.second;
    const double len = d.norm();
    if (len > tiny) {
      const Vec3 n = d / len;
      const double dist = len - r;
      if (dist > out.margin()) return;  // every other point is farther
      const int k = dominant_axis(n);
      const int e = dominant_axis(axis);
      if (std::abs(n[k]) >= kFaceCos) add_face_points(pb, half, p0, p1, k, sign_of(n[k]), r, 0.0, out);
      if (out.size() == 0 && std::abs(axis[e]) >= kParallelCos && std::abs(n[e]) <= kParallelSin) {
        // Core alongside the box edge along e (the gap direction is across
        // both): the two ends of the overlap, each with its exact closest
        // point on the box.
        std::array<Vec3, 2> ends{};
        const int m = overlap_along(p0, p1, half, e, kSameRel * out.scale(), ends);
        for (int i = 0; i < m; ++i) {
          const Vec3 x = ends[static_cast<std::size_t>(i)];
          const Vec3 y = clamp_to_box(x, half);
          const double len_xy = (x - y).norm();
          if (len_xy > tiny) add_local(pb, y, (x - y) / len_xy, len_xy - r, out);
        }
      }
      if (out.size() == 0 || out.min_dist() > dist + kSameRel * out.scale()) add_local(pb, cp.second, n, dist, out);
      return;
    }
  }

  // The core touches the box. Separating axis test of segment and box: the
  // box's 3 face normals and the segment's direction crossed with each box
  // axis are the face normals of their Minkowski sum, so the least overlap
  // among them is the exact penetration depth of the core.
  double face_sep = -std::numeric_limits<double>::infinity();
  int face = 0;
  for (int k = 0; k < 3; ++k) {
    const double sep = std::abs(c[k]) - a.half_length_m * std::abs(axis[k]) - half[k];
    if (sep > face_sep) {
      face_sep = sep;
      face = k;
    }
  }
  double edge_sep = -std::numeric_limits<double>::infinity();
  int edge = -1;
  Vec3 edge_dir = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    Vec3 l = axis.cross(Vec3::Unit(i));
    const double len = l.norm();
    if (len < 1e-6) continue;  // segment along this box axis: the face axes cover it
    l /= len;
    // The segment projects to a single point on l (l is perpendicular to it).
    const double sep = std::abs(c.dot(l)) - half.dot(l.cwiseAbs());
    if (sep > edge_sep) {
      edge_sep = sep;
      edge = i;
      edge_dir = l;
    }
  }

  const double prefer = kEdgeOverFaceRel * std::abs(face_sep) + kPreferAbs * half.minCoeff();
  const bool edge_wins = edge >= 0 && edge_sep > face_sep + prefer && std::abs(edge_dir[face]) < kEdgeFaceCos;
  // Face contact: the part of the core over the face, at its (negative) heights.
  const double side = sign_of(c[face]);
  const double any_height = -std::numeric_limits<double>::infinity();
  if (!edge_wins && add_face_points(pb, half, p0, p1, face, side, r, any_height, out)) return;
  if (edge >= 0) {
    // Edge contact (the edge axis won, or the core is not over the face):
    // the segment against the box edge along `edge` that supports the box
    // towards the capsule.
    const Vec3 l = c.dot(edge_dir) < 0.0 ? Vec3(-edge_dir) : edge_dir;
    Vec3 mid = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      if (j != edge) mid[j] = half[j] * sign_of(l[j]);
    }
    const Vec3 extent = half[edge] * Vec3::Unit(edge);
    const ClosestPair cp = closest_segments(p0, p1, mid - extent, mid + extent);
    const double dist = (cp.first - cp.second).dot(l) - r;
    if (std::abs(axis[edge]) >= kParallelCos) {
      // Nearly parallel to that edge: the two ends of the overlap.
      std::array<Vec3, 2> ends{};
      const int m = overlap_along(p0, p1, half, edge, kSameRel * out.scale(), ends);
      for (int i = 0; i < m; ++i) {
        const Vec3 x = ends[static_cast<std::size_t>(i)];
        const Vec3 q = closest_on_segment(mid - extent, mid + extent, x);
        add_local(pb, q, l, (x - q).dot(l) - r, out);
      }
    }
    if (out.size() == 0 || out.min_dist() > dist + kSameRel * out.scale()) add_local(pb, cp.second, l, dist, out);
    return;
  }
  // No edge axis and the core only grazing the box outside that face's prism
  // (touching within rounding): the closest pair, along the face normal.
  const ClosestPair cp = closest_segment_box(p0, p1, half);
  Vec3 normal = Vec3::Zero();
  normal[face] = side;
  add_local(pb, cp.second, normal, (cp.first - cp.second).dot(normal) - r, out);
}

}  // namespace tonus::sim::narrow
