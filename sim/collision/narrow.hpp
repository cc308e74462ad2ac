// Internal to the narrow phase: the candidate buffer each pair routine fills
// and the routines themselves. Not installed; sim/collision/*.cpp only.
//
// Every routine takes its shapes in canonical order (a's type <= b's type in
// ShapeType order, already validated) and writes points whose normal points
// from b towards a. collide() orders, dispatches, reduces to at most
// kMaxPointsPerPair and negates normals when it swapped the pair.
#pragma once

#include <array>
#include <cstddef>

#include "tonus/sim/collision.hpp"

namespace tonus::sim::narrow {

// Tolerances shared by the pair routines, relative to a length scale of the
// pair (see pair_scale) so the library behaves the same for a finger and a
// torso.
inline constexpr double kTinyRel = 1e-12;  // below this a core distance has no usable direction
inline constexpr double kSameRel = 1e-9;   // two candidate depths this close are the same depth

// A face manifold (box face under a capsule or a box) is added beside the
// exact closest pair when the pair's normal is within ~8 degrees of the face
// normal; each face point is still an exact pair of surface points.
inline constexpr double kFaceCos = 0.99;

// Segments or edges closer to parallel than this (sine of their angle) that
// overlap along their length make a line contact: a point at each end of the
// overlap, so a capsule lying along another, or along a box edge, rests on
// two points instead of rocking on one.
inline constexpr double kParallelSin = 0.02;
inline constexpr double kParallelCos = 0.999799979995999;  // sqrt(1 - kParallelSin^2)

// Feature preference when the shapes overlap: another box's face, or an edge
// axis, is taken over the current best face axis only if it separates by
// more than this (relative to the best face's depth, plus an absolute part in
// units of the smaller half extent). Keeps the manifold from flipping between
// near-equal axes from one step to the next, as Box2D/ODE/Bullet do.
inline constexpr double kFaceOverFaceRel = 0.02;
inline constexpr double kEdgeOverFaceRel = 0.05;
inline constexpr double kPreferAbs = 1e-5;
// An edge axis within 2 degrees of the best face normal never wins: the
// faces are nearly parallel (a slightly tilted cube on a palm, its low corner
// over the palm's edge), and clipping the face puts points at the edge with
// their true gaps, where an edge-edge contact would give a single point.
inline constexpr double kEdgeFaceCos = 0.99939082701909576;  // cos(2 degrees)

// Candidate points of one pair before the reduction to kMaxPointsPerPair.
class Candidates {
 public:
  static constexpr std::size_t kCapacity = 16;

  Candidates(double margin, double scale) : margin_(margin), scale_(scale) {}

  [[nodiscard]] double margin() const { return margin_; }
  // Length scale of the pair (largest bounding radius of its finite shapes).
  [[nodiscard]] double scale() const { return scale_; }
  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] const ContactPoint& operator[](std::size_t i) const { return points_[i]; }

  // Adds a point unless its gap exceeds the margin (or the buffer is full).
  // `pos` is the midpoint between the surfaces, `normal` unit from b to a.
  void add(const Vec3& pos, const Vec3& normal, double dist);

  // Same, given the surface point of b: the midpoint is on_b + normal*dist/2.
  void add_from_b(const Vec3& on_b, const Vec3& normal, double dist) {
    add(on_b + (0.5 * dist) * normal, normal, dist);
  }

  // Smallest gap among the points so far (+infinity when empty).
  [[nodiscard]] double min_dist() const;

 private:
  std::array<ContactPoint, kCapacity> points_{};
  std::size_t count_ = 0;
  double margin_;
  double scale_;
};

// Chooses at most k (<= kMaxPointsPerPair) of the candidates: the deepest
// first, then the points spanning the largest area in the contact plane.
// Writes their indices to idx and returns how many.
std::size_t reduce(const Candidates& c, std::size_t k, std::array<std::size_t, kMaxPointsPerPair>& idx);

// Pair routines, a.type <= b.type.
void sphere_sphere(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void sphere_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void capsule_capsule(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void sphere_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void capsule_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void box_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Candidates& out);
void sphere_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out);
void capsule_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out);
void box_plane(const Shape& a, const Pose& pa, const Pose& pb, Candidates& out);

// A capsule's core segment in world coordinates.
inline Vec3 capsule_end(const Shape& s, const Pose& p, double sign) {
  return p.pos + (sign * s.half_length_m) * p.rot.col(2);
}

}  // namespace tonus::sim::narrow
