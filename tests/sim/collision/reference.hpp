// Independent reference geometry for the narrow-phase tests. Nothing here is
// shared with sim/collision: signed distances come from a brute-force hull of
// the shapes' cores (no closest-feature case analysis, no separating-axis
// list), so a bug in the library's logic cannot hide in both.
#pragma once

#include <cstdint>
#include <random>

#include "tonus/sim/collision.hpp"

namespace tonus::sim::test {

// Deterministic random numbers (the raw engine is specified by the standard;
// the distributions are not, so they are written out here).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi);
  Vec3 unit_vector();
  Mat3 rotation();  // uniform over SO(3) (Shoemake)
  bool chance(double p) { return uniform(0.0, 1.0) < p; }

 private:
  std::mt19937_64 engine_;
};

// Signed distance from x to the shape's surface (negative inside).
double signed_distance(const Shape& s, const Pose& p, const Vec3& x);

// Support function max over the shape of x . u (finite shapes only).
double support(const Shape& s, const Pose& p, const Vec3& u);

// Signed distance of two finite shapes, computed without any of the
// library's closest-feature logic. Each shape is a core (sphere: its centre,
// capsule: its segment, box: itself) inflated by a radius. Overlapping cores:
// their Minkowski difference is a zonotope whose facet normals are the cross
// products of the generators (the cores' half axes), giving containment and
// depth directly. Apart cores: their distance by convex minimisation (golden
// section along a segment, or nested over each face of a box).
double reference_core_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

// Signed distance of a finite shape to a plane (its lowest point's height).
double reference_plane_gap(const Shape& a, const Pose& pa, const Pose& plane);

// Either of the above, by pair type.
double reference_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

struct Config {
  Shape a;
  Pose pa;
  Shape b;
  Pose pb;
  double margin = 0.0;
};

// Random shape sizes in the humanoid's range (centimetres to decimetres).
Shape random_shape(ShapeType t, Rng& rng);

// Two shapes of the given types placed near contact, from apart beyond the
// margin to deep overlap, with a random margin of up to 5 cm.
Config random_config(ShapeType ta, ShapeType tb, Rng& rng);

// Both poses moved by the same rigid transform.
Pose transformed(const Pose& t, const Pose& p);

const char* name(ShapeType t);

}  // namespace tonus::sim::test
