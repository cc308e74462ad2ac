// Rounded cores: sphere-sphere, sphere-capsule, capsule-capsule. Each shape is
// a point or a segment swept by its radius, so every contact is a closest pair
// of the cores pushed out by the radii.
#include <algorithm>
#include <cmath>

#include "closest.hpp"
#include "narrow.hpp"

namespace tonus::sim::narrow {
namespace {

struct RoundContact {
  Vec3 pos;
  Vec3 normal;
  double dist;
};

// Contact of two rounded cores given their closest points. When the cores
// meet (no direction between them) `fallback` is the normal; it must be unit.
RoundContact round_contact(const Vec3& core_a, const Vec3& core_b, double ra, double rb, const Vec3& fallback,
                           double tiny) {
  const Vec3 d = core_a - core_b;
  const double len = d.norm();
  const Vec3 n = len > tiny ? Vec3(d / len) : fallback;
  const double dist = d.dot(n) - ra - rb;
  return {core_b + (rb + 0.5 * dist) * n, n, dist};
}

void add(const RoundContact& c, Candidates& out) { out.add(c.pos, c.normal, c.dist); }

}  // namespace

void sphere_sphere(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  // Concentric spheres: any direction separates them equally; +z is as good as any.
  add(round_contact(pa.pos, pb.pos, a.radius_m, b.radius_m, Vec3::UnitZ(), kTinyRel * out.scale()), out);
}

void sphere_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  const Vec3 q = closest_on_segment(capsule_end(b, pb, -1.0), capsule_end(b, pb, 1.0), pa.pos);
  // Centre on the core: leave perpendicular to the capsule's axis.
  add(round_contact(pa.pos, q, a.radius_m, b.radius_m, pb.rot.col(0), kTinyRel * out.scale()), out);
}

void capsule_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out) {
  const double tiny = kTinyRel * out.scale();
  const Vec3 a0 = capsule_end(a, pa, -1.0);
  const Vec3 a1 = capsule_end(a, pa, 1.0);
  const Vec3 b0 = capsule_end(b, pb, -1.0);
  const Vec3 b1 = capsule_end(b, pb, 1.0);
  const Vec3 da = a1 - a0;
  const Vec3 db = b1 - b0;

  // Crossing cores separate fastest along the common normal of the two
  // axes; parallel ones along any perpendicular. Oriented from b to a.
  const Vec3 cross = da.cross(db);
  const double sin_angle = cross.norm() / (da.norm() * db.norm());
  Vec3 fallback = sin_angle > 1e-9 ? Vec3(cross.normalized()) : Vec3(pa.rot.col(0));
  if (fallback.dot(pa.pos - pb.pos) < 0.0) fallback = -fallback;

  const ClosestPair cp = closest_segments(a0, a1, b0, b1);
  const RoundContact closest = round_contact(cp.first, cp.second, a.radius_m, b.radius_m, fallback, tiny);
  if (closest.dist > out.margin()) return;  // every other point is farther

  if (sin_angle <= kParallelSin) {
    // Overlap of b's projection on a's axis, as parameters along a.
    const double len2 = da.squaredNorm();
    double s0 = (b0 - a0).dot(da) / len2;
    double s1 = (b1 - a0).dot(da) / len2;
    if (s0 > s1) std::swap(s0, s1);
    const double lo = std::max(0.0, s0);
    const double hi = std::min(1.0, s1);
    if ((hi - lo) * std::sqrt(len2) > kSameRel * out.scale()) {
      for (const double s : {lo, hi}) {
        const Vec3 x = a0 + s * da;
        add(round_contact(x, closest_on_segment(b0, b1, x), a.radius_m, b.radius_m, fallback, tiny), out);
      }
    }
  }
  // The closest pair, unless an overlap end is already as deep (parallel).
  if (out.size() == 0 || out.min_dist() > closest.dist + kSameRel * out.scale()) add(closest, out);
}

}  // namespace tonus::sim::narrow
