// Convex hulls of points on the ground and signed distances to them.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace tonus::indep {

using Point2 = Eigen::Vector2d;

// Andrew's monotone chain: the hull's vertices counter-clockwise, collinear
// and repeated points dropped; one or two points when the input is that
// degenerate, none for no input. Non-finite points are ignored.
[[nodiscard]] std::vector<Point2> convex_hull(std::vector<Point2> points);

// Distance from p to the hull (a point, a segment or a convex polygon as
// convex_hull gives it): positive outside, minus the distance to the nearest
// edge inside a polygon, zero on the boundary. Infinity for an empty hull.
// Widening the hull by a disc of radius r (a Minkowski sum) subtracts r.
[[nodiscard]] double signed_distance(const std::vector<Point2>& hull, const Point2& p);

}  // namespace tonus::indep
