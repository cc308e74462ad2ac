// Convex hull and nearest-point queries, exact for the small polygons (up to a
// few dozen vertices) of two feet.
#include "tonus/host/balance/polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tonus::balance {
namespace {

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

Vec2 nearest_on_segment(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0.0) return a;
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + t * ab;
}

bool inside(const ConvexPolygon& poly, const Vec2& p) {
  const auto& v = poly.vertices;
  if (v.size() < 3) return false;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (cross(v[i], v[(i + 1) % v.size()], p) < 0.0) return false;
  }
  return true;
}

Vec2 nearest_on_boundary(const ConvexPolygon& poly, const Vec2& p) {
  const auto& v = poly.vertices;
  if (v.size() == 1) return v[0];
  Vec2 best = v[0];
  double best_d2 = std::numeric_limits<double>::infinity();
  const std::size_t edges = v.size() == 2 ? 1 : v.size();
  for (std::size_t i = 0; i < edges; ++i) {
    const Vec2 q = nearest_on_segment(v[i], v[(i + 1) % v.size()], p);
    const double d2 = (q - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = q;
    }
  }
  return best;
}

}  // namespace

ConvexPolygon convex_hull(std::span<const Vec2> points) {
  std::vector<Vec2> pts;
  pts.reserve(points.size());
  for (const Vec2& p : points) {
    if (std::isfinite(p.x()) && std::isfinite(p.y())) pts.push_back(p);
  }
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  ConvexPolygon hull;
  if (pts.size() < 3) {
    hull.vertices = pts;
    return hull;
  }
  std::vector<Vec2> h(2 * pts.size());
  std::size_t k = 0;
  for (const Vec2& p : pts) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], p) <= 0.0) --k;
    h[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  hull.vertices = std::move(h);
  return hull;
}

double signed_distance(const ConvexPolygon& poly, const Vec2& p) {
  if (poly.empty()) return std::numeric_limits<double>::infinity();
  const double d = (nearest_on_boundary(poly, p) - p).norm();
  return inside(poly, p) ? -d : d;
}

Vec2 nearest_point(const ConvexPolygon& poly, const Vec2& p) {
  if (poly.empty()) return p;
  return inside(poly, p) ? p : nearest_on_boundary(poly, p);
}

Vec2 nearest_point_inset(const ConvexPolygon& poly, const Vec2& p, double inset) {
  Vec2 q = nearest_point(poly, p);
  if (poly.vertices.size() < 3 || inset <= 0.0 || q == p) return q;
  // Step inwards from q along the outward normal, reversed, halving the
  // depth until the point is that deep inside (a thin polygon allows less).
  const Vec2 n = (p - q).normalized();
  double d = inset;
  for (int halving = 0; halving < 20; ++halving, d *= 0.5) {
    Vec2 c = q - d * n;
    if (signed_distance(poly, c) <= -0.999 * d) return c;
  }
  return q;
}

}  // namespace tonus::balance
