// Convex hull and nearest-point queries, exact for the small polygons (up to a
// few dozen vertices) of two feet.
#include "tonus/host/balance/polygon.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

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

namespace {

// The hull of `pts` (finite, in any order; sorted and deduplicated here) into
// `out`, with `h` (twice as long as pts) as the chain's workspace.
void hull_of(std::span<Vec2> pts, std::span<Vec2> h, ConvexPolygon& out) {
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto n = static_cast<std::size_t>(std::unique(pts.begin(), pts.end()) - pts.begin());
  if (n < 3) {
    out.vertices.assign(pts.begin(), pts.begin() + static_cast<std::ptrdiff_t>(n));
    return;
  }
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = n - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
    h[k++] = pts[i];
  }
  out.vertices.assign(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(k - 1));
}

}  // namespace

void convex_hull(std::span<const Vec2> points, ConvexPolygon& out) {
  const auto finite = [](const Vec2& p) { return std::isfinite(p.x()) && std::isfinite(p.y()); };
  if (points.size() <= kHullInlinePoints) {
    std::array<Vec2, kHullInlinePoints> pts;
    std::array<Vec2, 2 * kHullInlinePoints> h;
    std::size_t n = 0;
    for (const Vec2& p : points) {
      if (finite(p)) pts[n++] = p;
    }
    hull_of(std::span<Vec2>(pts.data(), n), std::span<Vec2>(h.data(), 2 * n), out);
    return;
  }
  std::vector<Vec2> pts;
  pts.reserve(points.size());
  for (const Vec2& p : points) {
    if (finite(p)) pts.push_back(p);
  }
  std::vector<Vec2> h(2 * pts.size());
  hull_of(pts, h, out);
}

ConvexPolygon convex_hull(std::span<const Vec2> points) {
  ConvexPolygon hull;
  convex_hull(points, hull);
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
