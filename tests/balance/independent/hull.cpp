#include "independent/hull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tonus::indep {

namespace {

// > 0 when o -> a -> b turns left (counter-clockwise).
double cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

double segment_distance(const Point2& a, const Point2& b, const Point2& p) {
  const Point2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace

std::vector<Point2> convex_hull(std::vector<Point2> points) {
  // NaN would break the sort's ordering.
  std::erase_if(points, [](const Point2& p) { return !p.allFinite(); });
  std::sort(points.begin(), points.end(),
            [](const Point2& a, const Point2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Point2> hull(2 * points.size());
  std::size_t k = 0;
  for (const Point2& p : points) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

double signed_distance(const std::vector<Point2>& hull, const Point2& p) {
  if (hull.empty()) return std::numeric_limits<double>::infinity();
  if (hull.size() == 1) return (p - hull[0]).norm();
  double nearest = std::numeric_limits<double>::infinity();
  bool inside = hull.size() >= 3;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Point2& a = hull[i];
    const Point2& b = hull[(i + 1) % hull.size()];
    nearest = std::min(nearest, segment_distance(a, b, p));
    if (cross(a, b, p) < 0.0) inside = false;
  }
  return inside ? -nearest : nearest;
}

}  // namespace tonus::indep
