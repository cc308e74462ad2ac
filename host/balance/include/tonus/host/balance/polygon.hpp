// Convex polygons in the ground plane: the feet's soles and the support
// polygon (their convex hull), with the queries the balance filter needs.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "tonus/host/balance/landmarks.hpp"

namespace tonus::balance {

// Vertices counter-clockwise, no repeats; may be empty, a point or a segment.
struct ConvexPolygon {
  std::vector<Vec2> vertices;
  [[nodiscard]] bool empty() const { return vertices.empty(); }
};

// Andrew's monotone chain. Collinear points on the hull are dropped.
ConvexPolygon convex_hull(std::span<const Vec2> points);

// Up to this many points, the hull is taken in place (below).
inline constexpr std::size_t kHullInlinePoints = 64;
// The same into `out`, reusing its storage: it allocates nothing for at most
// kHullInlinePoints points when out.vertices has the capacity for them (the
// online filter's rings reserve it once).
void convex_hull(std::span<const Vec2> points, ConvexPolygon& out);

// Signed distance from p to the polygon's boundary: negative inside, positive
// outside (for a point or segment polygon: the plain distance). Infinite for an empty polygon.
double signed_distance(const ConvexPolygon& poly, const Vec2& p);

// The point of the polygon (boundary or inside) nearest to p: p itself when inside.
Vec2 nearest_point(const ConvexPolygon& poly, const Vec2& p);

// The point at distance `inset` inside the polygon, along the way from p to
// its nearest point (for targets kept off the very edge); the nearest point
// when the polygon is too thin for the inset.
Vec2 nearest_point_inset(const ConvexPolygon& poly, const Vec2& p, double inset);

}  // namespace tonus::balance
