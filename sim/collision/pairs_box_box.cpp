// Box-box: separating axis test over the 15 axes, reference/incident face
// clipping for face contacts, closest edge points for edge contacts, and the
// exact closest pair for boxes apart within the margin (where a separating
// axis only bounds the distance from below).
#include <array>
#include <cmath>
#include <limits>

#include "closest.hpp"
#include "narrow.hpp"

namespace tonus::sim::narrow {
namespace {

// Edge axes shorter than this (sine of the angle between the two edges) are
// skipped: parallel edges are covered by the face axes.
constexpr double kMinEdgeAxis = 1e-6;

using Polygon = std::array<Vec3, 8>;  // a quad clipped by 4 half-planes has at most 8 vertices

// Sutherland-Hodgman step: keeps the part of the polygon with side*x[axis] <= limit.
std::size_t clip_polygon(const Polygon& in, std::size_t n, int axis, double side, double limit, Polygon& out) {
  std::size_t m = 0;
  for (std::size_t i = 0; i < n && m < out.size(); ++i) {
    const Vec3& p = in[i];
    const Vec3& q = in[(i + 1) % n];
    const double dp = side * p[axis] - limit;
    const double dq = side * q[axis] - limit;
    if (dp <= 0.0) out[m++] = p;
    if (((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) && m < out.size()) out[m++] = p + (dp / (dp - dq)) * (q - p);
  }
  return m;
}

struct FaceContact {
  Vec3 on_incident;   // world
  Vec3 on_reference;  // world, on the reference face
  double height;      // of the incident point over the reference face
};
using FaceContacts = std::array<FaceContact, 8>;

// Clips the incident box's face most opposed to the reference face (axis
// `axis`, outward sign `side`, facing the incident box) against the side
// planes of the reference face. Returns how many points.
std::size_t clip_faces(const Pose& ref, const Vec3& ref_half, int axis, double side, const Pose& inc,
                       const Vec3& inc_half, FaceContacts& result) {
  const Mat3 rot = ref.rot.transpose() * inc.rot;  // incident axes in the reference frame
  const Vec3 centre = ref.inverse_apply(inc.pos);
  int m = 0;
  rot.row(axis).cwiseAbs().maxCoeff(&m);
  const double inc_side = -sign_of(side * rot(axis, m));
  const int u = (m + 1) % 3;
  const int v = (m + 2) % 3;
  const Vec3 face = centre + (inc_side * inc_half[m]) * rot.col(m);
  const Vec3 du = inc_half[u] * rot.col(u);
  const Vec3 dv = inc_half[v] * rot.col(v);

  Polygon poly = {face + du + dv, face - du + dv, face - du - dv, face + du - dv};
  std::size_t n = 4;
  Polygon tmp{};
  for (const int j : {(axis + 1) % 3, (axis + 2) % 3}) {
    for (const double s : {1.0, -1.0}) {
      n = clip_polygon(poly, n, j, s, ref_half[j], tmp);
      poly = tmp;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 on_ref = poly[i];
    on_ref[axis] = side * ref_half[axis];
    result[i] = {ref.apply(poly[i]), ref.apply(on_ref), side * poly[i][axis] - ref_half[axis]};
  }
  return n;
}

// Adds clipped face points; the contact normal points from b to a, and the
// reference face's outward normal `ref_normal` points at the incident box.
void add_face_contacts(const FaceContacts& pts, std::size_t n, const Vec3& ref_normal, bool ref_is_b, double min_height,
                       Candidates& out) {
  const Vec3 normal = ref_is_b ? ref_normal : Vec3(-ref_normal);
  for (std::size_t i = 0; i < n; ++i) {
    if (pts[i].height < min_height) continue;
    out.add(0.5 * (pts[i].on_incident + pts[i].on_reference), normal, pts[i].height);
  }
}

struct Axes {
  std::array<double, 3> face_a{};                          // separation along A's face normals
  std::array<double, 3> face_b{};                          // ... along B's
  double edge = -std::numeric_limits<double>::infinity();  // best edge axis
  int edge_i = -1;                                         // its A axis
  int edge_j = -1;                                         // its B axis
  Vec3 edge_dir = Vec3::Zero();                            // unit, A's frame
  double max_sep = -std::numeric_limits<double>::infinity();
};

// Separations along the 15 axes, B given in A's frame (rotation r, centre t).
Axes separating_axes(const Vec3& ha, const Vec3& hb, const Mat3& r, const Vec3& t) {
  Axes ax;
  const Mat3 abs_r = r.cwiseAbs();
  const Vec3 tb = r.transpose() * t;
  for (int i = 0; i < 3; ++i) {
    ax.face_a[static_cast<std::size_t>(i)] = std::abs(t[i]) - ha[i] - abs_r.row(i).dot(hb);
    ax.face_b[static_cast<std::size_t>(i)] = std::abs(tb[i]) - hb[i] - abs_r.col(i).dot(ha);
    ax.max_sep = std::max({ax.max_sep, ax.face_a[static_cast<std::size_t>(i)], ax.face_b[static_cast<std::size_t>(i)]});
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Vec3 l = Vec3::Unit(i).cross(r.col(j));
      const double len = l.norm();
      if (len < kMinEdgeAxis) continue;
      l /= len;
      const double sep = std::abs(t.dot(l)) - ha.dot(l.cwiseAbs()) - hb.dot((r.transpose() * l).cwiseAbs());
      if (sep > ax.edge) {
        ax.edge = sep;
        ax.edge_i = i;
        ax.edge_j = j;
        ax.edge_dir = l;
      }
    }
  }
  ax.max_sep = std::max(ax.max_sep, ax.edge);
  return ax;
}

int argmax(const std::array<double, 3>& v) {
  int k = 0;
  for (int i = 1; i < 3; ++i) {
    if (v[static_cast<std::size_t>(i)] > v[static_cast<std::size_t>(k)]) k = i;
  }
  return k;
}

}  // namespace

void box_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  const Vec3& ha = a.half_extents_m;
  const Vec3& hb = b.half_extents_m;
  const Mat3 r = pa.rot.transpose() * pb.rot;  // B's axes in A's frame
  const Vec3 t = pa.inverse_apply(pb.pos);     // B's centre in A's frame
  const Axes ax = separating_axes(ha, hb, r, t);
  // Any separating axis bounds the distance from below.
  if (ax.max_sep > out.margin()) return;

  // Reference face: A's best, unless B's is clearly better (hysteresis).
  const int ia = argmax(ax.face_a);
  const int jb = argmax(ax.face_b);
  const double sep_a = ax.face_a[static_cast<std::size_t>(ia)];
  const double sep_b = ax.face_b[static_cast<std::size_t>(jb)];
  const double abs_tol = kPreferAbs * std::min(ha.minCoeff(), hb.minCoeff());
  const bool ref_is_b = sep_b > sep_a + kFaceOverFaceRel * std::abs(sep_a) + abs_tol;
  const double face_sep = ref_is_b ? sep_b : sep_a;

  // Clips with a face of A (ref_b false) or B as reference; side from its
  // normal towards the other box.
  FaceContacts pts{};
  const auto clip = [&](bool on_b, int axis, double side) -> std::size_t {
    return on_b ? clip_faces(pb, hb, axis, side, pa, ha, pts) : clip_faces(pa, ha, axis, side, pb, hb, pts);
  };
  const auto ref_normal = [&](bool on_b, int axis, double side) -> Vec3 {
    return side * (on_b ? pb.rot.col(axis) : pa.rot.col(axis));
  };
  const Vec3 tb = r.transpose() * t;
  const int ref_axis = ref_is_b ? jb : ia;
  const double ref_side = ref_is_b ? -sign_of(tb[jb]) : sign_of(t[ia]);

  if (ax.max_sep > kTinyRel * out.scale()) {
    // Apart. If the face manifold reaches down to the separating-axis bound,
    // it holds a pair of surface points that far apart, so that is the exact
    // distance (the usual face-on-face case) and we are done.
    const std::size_t n = clip(ref_is_b, ref_axis, ref_side);
    double lowest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) lowest = std::min(lowest, pts[i].height);
    if (n > 0 && lowest <= ax.max_sep + kSameRel * out.scale()) {
      add_face_contacts(pts, n, ref_normal(ref_is_b, ref_axis, ref_side), ref_is_b, 0.0, out);
      return;
    }
    // Otherwise edges or corners are closest: the exact closest pair, plus
    // the face manifold when that pair is nearly along a face normal.
    const ClosestPair cp = closest_box_box(ha, r, t, hb);
    const Vec3 d = cp.first - cp.second;  // A's frame, from B to A
    const double dist = d.norm();
    if (dist > out.margin()) return;
    const Vec3 n_a = d / dist;
    const Vec3 n_b = r.transpose() * n_a;
    int ka = 0;
    int kb = 0;
    const double align_a = n_a.cwiseAbs().maxCoeff(&ka);
    const double align_b = n_b.cwiseAbs().maxCoeff(&kb);
    const double tol = kSameRel * out.scale();
    // A pair of (nearly) parallel edges with the gap direction across both.
    int edge_a = -1;
    int edge_b = -1;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (std::abs(r(i, j)) >= kParallelCos && std::abs(n_a[i]) <= kParallelSin) {
          edge_a = i;
          edge_b = j;
        }
      }
    }
    if (std::max(align_a, align_b) >= kFaceCos) {
      const bool on_b = align_b > align_a;
      // The reference face looks at the other box: A's against n, B's along it.
      const int axis = on_b ? kb : ka;
      const double side = on_b ? sign_of(n_b[kb]) : -sign_of(n_a[ka]);
      const std::size_t m = clip(on_b, axis, side);
      add_face_contacts(pts, m, ref_normal(on_b, axis, side), on_b, 0.0, out);
    }
    if (out.size() == 0 && edge_a >= 0) {
      // The ends of the overlap along A's edge facing B, each with its exact
      // closest point on B.
      Vec3 mid_a = Vec3::Zero();
      Vec3 mid_b = Vec3::Zero();  // B's frame
      for (int k = 0; k < 3; ++k) {
        if (k != edge_a) mid_a[k] = -ha[k] * sign_of(n_a[k]);
        if (k != edge_b) mid_b[k] = hb[k] * sign_of(n_b[k]);
      }
      const Vec3 ext_b = r.col(edge_b) * hb[edge_b];
      const double b0 = (t + r * mid_b - ext_b)[edge_a];
      const double b1 = (t + r * mid_b + ext_b)[edge_a];
      const double lo = std::max(-ha[edge_a], std::min(b0, b1));
      const double hi = std::min(ha[edge_a], std::max(b0, b1));
      for (const double s : {lo, hi}) {
        if (lo > hi || (s == hi && hi - lo <= tol)) break;  // no overlap, or a single point
        Vec3 x = mid_a;
        x[edge_a] = s;
        const Vec3 y = t + r * clamp_to_box(r.transpose() * (x - t), hb);
        const double len = (x - y).norm();
        if (len > kTinyRel * out.scale()) out.add_from_b(pa.apply(y), pa.rot * ((x - y) / len), len);
      }
    }
    if (out.size() == 0 || out.min_dist() > dist + kSameRel * out.scale()) {
      out.add_from_b(pa.apply(cp.second), pa.rot * n_a, dist);
    }
    return;
  }

  // Overlapping (or touching): the least-penetration axis, faces preferred.
  const Vec3 face_dir = ref_is_b ? Vec3(r.col(ref_axis)) : Vec3(Vec3::Unit(ref_axis));  // A's frame
  const bool edge_wins = ax.edge_i >= 0 && ax.edge > face_sep + kEdgeOverFaceRel * std::abs(face_sep) + abs_tol &&
                         std::abs(ax.edge_dir.dot(face_dir)) < kEdgeFaceCos;
  const std::size_t n = edge_wins ? 0 : clip(ref_is_b, ref_axis, ref_side);
  const Vec3 normal = ref_normal(ref_is_b, ref_axis, ref_side);
  if (n > 0) {
    add_face_contacts(pts, n, normal, ref_is_b, -std::numeric_limits<double>::infinity(), out);
    return;
  }
  if (ax.edge_i >= 0) {
    // Edge-edge (the edge axis won, or the preferred face's clip was empty):
    // the edge of A supporting towards B against the edge of B supporting
    // towards A, each along its axis of the cross product.
    const Vec3 l = t.dot(ax.edge_dir) < 0.0 ? Vec3(-ax.edge_dir) : ax.edge_dir;  // A to B
    const Vec3 lb = r.transpose() * l;
    Vec3 mid_a = Vec3::Zero();
    Vec3 mid_b = Vec3::Zero();  // B's frame
    for (int k = 0; k < 3; ++k) {
      if (k != ax.edge_i) mid_a[k] = ha[k] * sign_of(l[k]);
      if (k != ax.edge_j) mid_b[k] = -hb[k] * sign_of(lb[k]);
    }
    const Vec3 ext_a = ha[ax.edge_i] * Vec3::Unit(ax.edge_i);
    const Vec3 ext_b = hb[ax.edge_j] * Vec3::Unit(ax.edge_j);
    const Vec3 b0 = t + r * (mid_b - ext_b);
    const Vec3 b1 = t + r * (mid_b + ext_b);
    const ClosestPair cp = closest_segments(mid_a - ext_a, mid_a + ext_a, b0, b1);
    const Vec3 n_ba = -l;  // from B to A
    const double dist = (cp.first - cp.second).dot(n_ba);
    if (std::abs(r(ax.edge_i, ax.edge_j)) >= kParallelCos) {
      // Nearly parallel edges: the two ends of their overlap along A's edge.
      const double lo = std::max(-ha[ax.edge_i], std::min(b0[ax.edge_i], b1[ax.edge_i]));
      const double hi = std::min(ha[ax.edge_i], std::max(b0[ax.edge_i], b1[ax.edge_i]));
      for (const double s : {lo, hi}) {
        if (lo > hi || (s == hi && hi - lo <= kSameRel * out.scale())) break;  // no overlap, or a single point
        Vec3 x = mid_a;
        x[ax.edge_i] = s;
        const Vec3 y = closest_on_segment(b0, b1, x);
        out.add_from_b(pa.apply(y), pa.rot * n_ba, (x - y).dot(n_ba));
      }
    }
    if (out.size() == 0 || out.min_dist() > dist + kSameRel * out.scale()) {
      out.add_from_b(pa.apply(cp.second), pa.rot * n_ba, dist);
    }
    return;
  }
  // No edge axis and the incident face entirely outside the reference
  // face's prism (touching within rounding): the incident corner deepest
  // along the reference normal.
  const Pose& ref = ref_is_b ? pb : pa;
  const Pose& inc = ref_is_b ? pa : pb;
  const Vec3& ref_half = ref_is_b ? hb : ha;
  const Vec3& inc_half = ref_is_b ? ha : hb;
  const Vec3 down = inc.rot.transpose() * (-normal);
  const Vec3 corner = inc.apply(inc_half.cwiseProduct(Vec3(sign_of(down.x()), sign_of(down.y()), sign_of(down.z()))));
  const double height = normal.dot(corner - ref.pos) - ref_half[ref_axis];
  add_face_contacts({FaceContact{corner, corner - height * normal, height}}, 1, normal, ref_is_b,
                    -std::numeric_limits<double>::infinity(), out);
}

}  // namespace tonus::sim::narrow
