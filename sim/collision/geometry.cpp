// Shape sizes: bounding radius and validity.
#include "tonus/sim/geometry.hpp"

#include <cmath>
#include <limits>

namespace tonus::sim {
namespace {

bool positive_finite(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

double bounding_radius(const Shape& s) {
  switch (s.type) {
    case ShapeType::sphere: return s.radius_m;
    case ShapeType::capsule: return s.half_length_m + s.radius_m;
    case ShapeType::box: return s.half_extents_m.norm();
    case ShapeType::plane: return std::numeric_limits<double>::infinity();
  }
  return 0.0;  // not a ShapeType value
}

bool shape_is_valid(const Shape& s) {
  switch (s.type) {
    case ShapeType::sphere: return positive_finite(s.radius_m);
    case ShapeType::capsule: return positive_finite(s.radius_m) && positive_finite(s.half_length_m);
    case ShapeType::box:
      return positive_finite(s.half_extents_m.x()) && positive_finite(s.half_extents_m.y()) &&
             positive_finite(s.half_extents_m.z());
    case ShapeType::plane: return true;
  }
  return false;  // not a ShapeType value
}

}  // namespace tonus::sim
