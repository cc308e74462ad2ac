// Independent reference geometry (see reference.hpp).
#include "reference.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

namespace tonus::sim::test {

double Rng::uniform(double lo, double hi) {
  // 53 random bits -> [0, 1).
  const double u = static_cast<double>(engine_() >> 11U) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

Vec3 Rng::unit_vector() {
  const double z = uniform(-1.0, 1.0);
  const double phi = uniform(0.0, 2.0 * std::numbers::pi);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

Mat3 Rng::rotation() {
  const double u1 = uniform(0.0, 1.0);
  const double u2 = uniform(0.0, 2.0 * std::numbers::pi);
  const double u3 = uniform(0.0, 2.0 * std::numbers::pi);
  const double a = std::sqrt(1.0 - u1);
  const double b = std::sqrt(u1);
  const Quat q(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3));
  return q.normalized().toRotationMatrix();
}

namespace {

// The capsule's core: closest point of its segment to x.
Vec3 core_point(const Shape& s, const Pose& p, const Vec3& x) {
  const Vec3 axis = p.rot.col(2);
  const double t = std::clamp(axis.dot(x - p.pos), -s.half_length_m, s.half_length_m);
  return p.pos + t * axis;
}

}  // namespace

double signed_distance(const Shape& s, const Pose& p, const Vec3& x) {
  switch (s.type) {
    case ShapeType::sphere: return (x - p.pos).norm() - s.radius_m;
    case ShapeType::capsule: return (x - core_point(s, p, x)).norm() - s.radius_m;
    case ShapeType::box: {
      const Vec3 q = p.inverse_apply(x).cwiseAbs() - s.half_extents_m;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case ShapeType::plane: return p.rot.col(2).dot(x - p.pos);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double support(const Shape& s, const Pose& p, const Vec3& u) {
  switch (s.type) {
    case ShapeType::sphere: return p.pos.dot(u) + s.radius_m;
    case ShapeType::capsule: return p.pos.dot(u) + s.half_length_m * std::abs(p.rot.col(2).dot(u)) + s.radius_m;
    case ShapeType::box: return p.pos.dot(u) + s.half_extents_m.dot((p.rot.transpose() * u).cwiseAbs());
    case ShapeType::plane: return std::numeric_limits<double>::infinity();
  }
  return std::numeric_limits<double>::quiet_NaN();
}

namespace {

double point_segment_distance(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((x - p).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (x - (p + t * d)).norm();
}

double point_box_distance(const Shape& box, const Pose& p, const Vec3& x) {
  const Vec3 q = p.inverse_apply(x);
  return (q - q.cwiseMax(-box.half_extents_m).cwiseMin(box.half_extents_m)).norm();
}

// Minimum of a convex function on [lo, hi] by golden-section search.
template <typename F>
double golden_min(F f, double lo, double hi) {
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = hi - g * (hi - lo);
  double x2 = lo + g * (hi - lo);
  double f1 = f(x1);
  double f2 = f(x2);
  double best = std::min({f(lo), f(hi), f1, f2});
  for (int it = 0; it < 64; ++it) {  // bracket shrinks to 0.618^64 = 4e-14 of the range
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = f(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = f(x2);
    }
    best = std::min({best, f1, f2});
  }
  return best;
}

// The shape's core as a zonotope: centre plus generators (a point has none,
// a segment one, a box three), and the radius inflating it.
struct Core {
  Vec3 centre;
  std::vector<Vec3> generators;
  double radius;
};

Core core_of(const Shape& s, const Pose& p) {
  switch (s.type) {
    case ShapeType::sphere: return {p.pos, {}, s.radius_m};
    case ShapeType::capsule: return {p.pos, {s.half_length_m * p.rot.col(2)}, s.radius_m};
    case ShapeType::box:
      return {p.pos,
              {s.half_extents_m.x() * p.rot.col(0), s.half_extents_m.y() * p.rot.col(1),
               s.half_extents_m.z() * p.rot.col(2)},
              0.0};
    case ShapeType::plane: break;
  }
  return {p.pos, {}, 0.0};
}

// Distance between the cores (0 when they intersect), each computed by the
// most direct convex minimisation available.
double core_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (a.type > b.type) return core_distance(b, pb, a, pa);
  const auto seg = [](const Pose& p, double t) { return Vec3(p.pos + t * p.rot.col(2)); };
  const Vec3 b0 = seg(pb, -b.half_length_m);
  const Vec3 b1 = seg(pb, b.half_length_m);
  switch (a.type) {
    case ShapeType::sphere:
      if (b.type == ShapeType::sphere) return (pa.pos - pb.pos).norm();
      if (b.type == ShapeType::capsule) return point_segment_distance(pa.pos, b0, b1);
      return point_box_distance(b, pb, pa.pos);
    case ShapeType::capsule:
      // Distance from a point moving along a's segment to b's core is convex.
      if (b.type == ShapeType::capsule) {
        return golden_min([&](double t) { return point_segment_distance(seg(pa, t), b0, b1); }, -a.half_length_m,
                          a.half_length_m);
      }
      return golden_min([&](double t) { return point_box_distance(b, pb, seg(pa, t)); }, -a.half_length_m,
                        a.half_length_m);
    case ShapeType::box: {
      // Disjoint boxes: the closest point of A lies on one of its faces, and
      // the distance to B is convex over each face (nested golden sections).
      double best = std::numeric_limits<double>::infinity();
      const Vec3& h = a.half_extents_m;
      for (int k = 0; k < 3; ++k) {
        const int u = (k + 1) % 3;
        const int v = (k + 2) % 3;
        for (const double side : {-1.0, 1.0}) {
          const auto at = [&](double x, double y) {
            Vec3 local = Vec3::Zero();
            local[k] = side * h[k];
            local[u] = x;
            local[v] = y;
            return point_box_distance(b, pb, pa.apply(local));
          };
          best = std::min(
              best, golden_min([&](double x) { return golden_min([&](double y) { return at(x, y); }, -h[v], h[v]); },
                               -h[u], h[u]));
        }
      }
      return best;
    }
    case ShapeType::plane: break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// Cores as the zonotope M = core_a - core_b. Its facet normals are the cross
// products of pairs of generators, so the origin is inside M iff its support
// is non-negative along all of them, and then the least of those supports is
// the depth (the minimum translation separating the cores).
struct ZonotopeQuery {
  bool full_dimensional = false;
  bool contains_origin = false;
  double depth = 0.0;
};

ZonotopeQuery origin_in_difference(const Core& ca, const Core& cb) {
  std::vector<Vec3> g = ca.generators;
  g.insert(g.end(), cb.generators.begin(), cb.generators.end());
  const Vec3 c = ca.centre - cb.centre;
  const auto support = [&](const Vec3& n) {
    double s = c.dot(n);
    for (const Vec3& x : g) s += std::abs(x.dot(n));
    return s;
  };
  ZonotopeQuery q;
  q.depth = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (std::size_t j = i + 1; j < g.size(); ++j) {
      const Vec3 n = g[i].cross(g[j]);
      if (n.norm() <= 1e-9 * g[i].norm() * g[j].norm()) continue;  // (nearly) parallel generators
      const Vec3 u = n.normalized();
      q.depth = std::min({q.depth, support(u), support(-u)});
      // Three independent generators span space.
      for (std::size_t k = 0; k < g.size(); ++k) {
        q.full_dimensional = q.full_dimensional || std::abs(u.dot(g[k])) > 1e-9 * g[k].norm();
      }
    }
  }
  q.contains_origin = q.full_dimensional && q.depth >= 0.0;
  return q;
}

}  // namespace

double reference_core_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  const Core ca = core_of(a, pa);
  const Core cb = core_of(b, pb);
  const double radii = ca.radius + cb.radius;
  const ZonotopeQuery z = origin_in_difference(ca, cb);
  if (z.contains_origin) return -z.depth - radii;
  // Lower-dimensional cores (point, segment pairs) that meet separate along
  // a direction normal to both, at zero core depth.
  return core_distance(a, pa, b, pb) - radii;
}

double reference_plane_gap(const Shape& a, const Pose& pa, const Pose& plane) {
  const Vec3 n = plane.rot.col(2);
  return -support(a, pa, -n) - n.dot(plane.pos);
}

double reference_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (b.type == ShapeType::plane) return reference_plane_gap(a, pa, pb);
  if (a.type == ShapeType::plane) return reference_plane_gap(b, pb, pa);
  return reference_core_signed_distance(a, pa, b, pb);
}

Shape random_shape(ShapeType t, Rng& rng) {
  switch (t) {
    case ShapeType::sphere: return Shape::sphere(rng.uniform(0.02, 0.3));
    case ShapeType::capsule: return Shape::capsule(rng.uniform(0.01, 0.15), rng.uniform(0.02, 0.4));
    case ShapeType::box: return Shape::box({rng.uniform(0.01, 0.4), rng.uniform(0.01, 0.4), rng.uniform(0.01, 0.4)});
    case ShapeType::plane: return Shape::plane();
  }
  return {};
}

namespace {

// Rotations that make faces and axes parallel or nearly so, the degenerate
// cases random rotations never hit.
Mat3 structured_rotation(Rng& rng) {
  Mat3 r = Mat3::Identity();
  const double pick = rng.uniform(0.0, 1.0);
  if (pick < 0.25) return r;
  if (pick < 0.5) {
    // A signed permutation (90 degree turns).
    std::array<int, 3> perm = {0, 1, 2};
    for (int i = 2; i > 0; --i)
      std::swap(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(rng.uniform(0.0, i + 1.0))]);
    r.setZero();
    for (std::size_t i = 0; i < 3; ++i) r(static_cast<Eigen::Index>(i), perm[i]) = rng.chance(0.5) ? 1.0 : -1.0;
    if (r.determinant() < 0.0) r.col(0) = -r.col(0);
    return r;
  }
  // A small tilt about a random axis.
  const double angle = rng.uniform(-0.05, 0.05) * (rng.chance(0.5) ? 1.0 : 1e-4);
  return quat_exp(angle * rng.unit_vector()).toRotationMatrix();
}

}  // namespace

Config random_config(ShapeType ta, ShapeType tb, Rng& rng) {
  Config c;
  c.a = random_shape(ta, rng);
  c.b = random_shape(tb, rng);
  c.margin = rng.uniform(0.0, 0.05);
  Pose base{Vec3(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)), rng.rotation()};
  const bool structured = rng.chance(0.35);
  if (ta == ShapeType::plane || tb == ShapeType::plane) {
    // The finite shape at a random height over the plane, from half its size
    // deep to beyond the margin.
    const bool a_is_plane = ta == ShapeType::plane;
    const Shape& s = a_is_plane ? c.b : c.a;
    const double rad = bounding_radius(s);
    const Vec3 n = base.rot.col(2);
    Pose p;
    p.rot = structured ? Mat3(base.rot * structured_rotation(rng)) : rng.rotation();
    const Vec3 tangent = base.rot.col(0) * rng.uniform(-1.0, 1.0) + base.rot.col(1) * rng.uniform(-1.0, 1.0);
    p.pos = base.pos + tangent + n * rng.uniform(-0.5 * rad, rad + 0.06);
    c.pa = a_is_plane ? base : p;
    c.pb = a_is_plane ? p : base;
    return c;
  }
  c.pb = base;
  c.pa.rot = structured ? Mat3(base.rot * structured_rotation(rng)) : rng.rotation();
  Vec3 dir = rng.unit_vector();
  if (structured && rng.chance(0.5)) {
    // Along one of b's axes: stacked faces and side-by-side capsules.
    const Eigen::Index axis = std::min<Eigen::Index>(2, static_cast<Eigen::Index>(rng.uniform(0.0, 3.0)));
    dir = base.rot.col(axis) * (rng.chance(0.5) ? 1.0 : -1.0) + 0.3 * rng.uniform(0.0, 1.0) * rng.unit_vector();
    dir.normalize();
  }
  // Along dir the projections of the two shapes stop overlapping at `reach`:
  // beyond it they are apart, up to 6 cm (past any margin); below it they
  // are close to touching or overlapping.
  const double reach =
      support(c.b, Pose{Vec3::Zero(), base.rot}, dir) + support(c.a, Pose{Vec3::Zero(), c.pa.rot}, -dir);
  c.pa.pos = base.pos + dir * (reach + rng.uniform(-0.4 * reach, 0.08));
  return c;
}

Pose transformed(const Pose& t, const Pose& p) { return {t.apply(p.pos), t.rot * p.rot}; }

const char* name(ShapeType t) {
  switch (t) {
    case ShapeType::sphere: return "sphere";
    case ShapeType::capsule: return "capsule";
    case ShapeType::box: return "box";
    case ShapeType::plane: return "plane";
  }
  return "?";
}

}  // namespace tonus::sim::test
