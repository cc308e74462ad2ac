// collide(): input checks, canonical pair order, dispatch, reduction.
#include "tonus/sim/collision.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "narrow.hpp"

namespace tonus::sim {
namespace {

// A rotation's columns must be orthonormal to this (element-wise on
// R^T R - I) and right-handed; quaternion-built rotations are at ~1e-15.
constexpr double kRotationTol = 1e-6;

bool pose_is_valid(const Pose& p) {
  if (!all_finite(p.pos) || !p.rot.allFinite()) return false;
  const Mat3 err = p.rot.transpose() * p.rot - Mat3::Identity();
  return err.cwiseAbs().maxCoeff() <= kRotationTol && p.rot.determinant() > 0.0;
}

// Strict weak order on posed shapes: type, then sizes, then pose. The pair is
// always evaluated with the smaller first, so swapping a and b runs the very
// same arithmetic and only the normals' sign changes. Sizes before pose so
// that, for different shapes, moving both rigidly never changes the roles.
bool canonical_first(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (a.type != b.type) return a.type < b.type;
  const auto key = [](const Shape& s, const Pose& p) {
    return std::array<double, 17>{
        s.radius_m,  s.half_length_m, s.half_extents_m.x(), s.half_extents_m.y(), s.half_extents_m.z(), p.pos.x(),
        p.pos.y(),   p.pos.z(),       p.rot(0, 0),          p.rot(1, 0),          p.rot(2, 0),          p.rot(0, 1),
        p.rot(1, 1), p.rot(2, 1),     p.rot(0, 2),          p.rot(1, 2),          p.rot(2, 2)};
  };
  const auto ka = key(a, pa);
  const auto kb = key(b, pb);
  for (std::size_t i = 0; i < ka.size(); ++i) {
    if (ka[i] != kb[i]) return ka[i] < kb[i];
  }
  return true;
}

double pair_scale(const Shape& a, const Shape& b) {
  double s = 0.0;
  if (a.type != ShapeType::plane) s = std::max(s, bounding_radius(a));
  if (b.type != ShapeType::plane) s = std::max(s, bounding_radius(b));
  return s;
}

void dispatch(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, narrow::Candidates& c) {
  using ST = ShapeType;
  switch (a.type) {
    case ST::sphere:
      switch (b.type) {
        case ST::sphere: narrow::sphere_sphere(a, pa, b, pb, c); return;
        case ST::capsule: narrow::sphere_capsule(a, pa, b, pb, c); return;
        case ST::box: narrow::sphere_box(a, pa, b, pb, c); return;
        case ST::plane: narrow::sphere_plane(a, pa, pb, c); return;
      }
      return;
    case ST::capsule:
      switch (b.type) {
        case ST::capsule: narrow::capsule_capsule(a, pa, b, pb, c); return;
        case ST::box: narrow::capsule_box(a, pa, b, pb, c); return;
        case ST::plane: narrow::capsule_plane(a, pa, pb, c); return;
        case ST::sphere: return;  // not canonical
      }
      return;
    case ST::box:
      switch (b.type) {
        case ST::box: narrow::box_box(a, pa, b, pb, c); return;
        case ST::plane: narrow::box_plane(a, pa, pb, c); return;
        case ST::sphere:
        case ST::capsule: return;  // not canonical
      }
      return;
    case ST::plane: return;  // plane-plane: two infinite planes have no contact points
  }
}

bool finite(const ContactPoint& p) { return all_finite(p.pos) && all_finite(p.normal) && std::isfinite(p.dist_m); }

}  // namespace

std::size_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b, double margin_m,
                    std::span<ContactPoint> out) {
  if (out.empty() || !std::isfinite(margin_m)) return 0;
  if (!shape_is_valid(a) || !shape_is_valid(b) || !pose_is_valid(pose_a) || !pose_is_valid(pose_b)) return 0;

  const bool swapped = !canonical_first(a, pose_a, b, pose_b);
  narrow::Candidates candidates(margin_m, pair_scale(a, b));
  if (swapped) {
    dispatch(b, pose_b, a, pose_a, candidates);
  } else {
    dispatch(a, pose_a, b, pose_b, candidates);
  }

  std::array<std::size_t, kMaxPointsPerPair> idx{};
  const std::size_t n = narrow::reduce(candidates, out.size(), idx);
  std::size_t written = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ContactPoint p = candidates[idx[i]];
    if (swapped) p.normal = -p.normal;
    // Last line of defence: overflowing sizes or poses never leak NaN/inf.
    if (finite(p)) out[written++] = p;
  }
  return written;
}

}  // namespace tonus::sim
