// Collision detection: which shapes touch (or will within a step), turned
// into Contacts between sides (body, object, ground), warm-started from the
// previous step's contacts at the same place.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "spatial.hpp"
#include "stages.hpp"
#include "tonus/sim/collision.hpp"

namespace tonus::sim::detail {
namespace {

using std::size_t;

struct Candidate {
  const Shape* shape;
  Pose pose;
  ContactSide side;
  Material material;
  double sweep_m;  // how far any point of it may move in one step
};

Pose ground_pose(const Ground& g) {
  Pose p;
  p.pos = g.normal * g.offset_m;
  // Any rotation taking z onto the normal.
  p.rot = Quat::FromTwoVectors(Vec3::UnitZ(), g.normal).toRotationMatrix();
  return p;
}

// Coulomb coefficients combine as a geometric mean (Box2D, Bullet): equal
// materials keep their value, and ice on anything stays slippery.
double combine_friction(double a, double b) { return std::sqrt(a * b); }
double combine_restitution(double a, double b) { return std::max(a, b); }

void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  const Vec3 axis =
      std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : (std::abs(n.y()) < 0.57735 ? Vec3::UnitY() : Vec3::UnitZ());
  t1 = n.cross(axis).normalized();
  t2 = n.cross(t1);
}

bool same_side(const ContactSide& x, const ContactSide& y) {
  return x.kind == y.kind && x.index == y.index && x.geom == y.geom;
}

// Last step's impulse at (nearly) the same place between the same sides.
void warm_start(const Data& data, Contact& c) {
  constexpr double kMatchDistance = 0.02;  // m
  double best = kMatchDistance * kMatchDistance;
  const Contact* match = nullptr;
  for (int i = 0; i < data.prev_ncon; ++i) {
    const Contact& p = data.prev_contacts[static_cast<size_t>(i)];
    if (!same_side(p.a, c.a) || !same_side(p.b, c.b)) continue;
    const double d2 = (p.pos - c.pos).squaredNorm();
    if (d2 < best) {
      best = d2;
      match = &p;
    }
  }
  if (match == nullptr) {
    c.impulse.setZero();
    return;
  }
  const Vec3 friction_world = match->impulse.y() * match->tangent1 + match->impulse.z() * match->tangent2;
  c.impulse = Vec3(match->impulse.x(), friction_world.dot(c.tangent1), friction_world.dot(c.tangent2));
}

class Collector {
 public:
  Collector(const Model& model, Data& data) : model_(model), data_(data) {}

  void pair(const Candidate& a, const Candidate& b) {
    const double margin = model_.solver.contact_margin_m + a.sweep_m + b.sweep_m;
    const bool a_plane = a.shape->type == ShapeType::plane, b_plane = b.shape->type == ShapeType::plane;
    if (!a_plane && !b_plane) {
      const double reach = bounding_radius(*a.shape) + bounding_radius(*b.shape) + margin;
      if ((a.pose.pos - b.pose.pos).squaredNorm() > reach * reach) return;
    } else if (b_plane) {
      const Vec3 n = b.pose.rot.col(2);
      if (n.dot(a.pose.pos - b.pose.pos) > bounding_radius(*a.shape) + margin) return;
    }
    std::array<ContactPoint, kMaxPointsPerPair> points;
    const size_t n = collide(*a.shape, a.pose, *b.shape, b.pose, margin, points);
    for (size_t k = 0; k < n; ++k) {
      if (data_.ncon >= static_cast<int>(kMaxContacts)) {
        ++data_.diag.contact_overflow;
        continue;
      }
      Contact& c = data_.contacts[static_cast<size_t>(data_.ncon++)];
      c.a = a.side;
      c.b = b.side;
      c.pos = points[k].pos;
      c.normal = points[k].normal;
      c.dist_m = points[k].dist_m;
      tangent_basis(c.normal, c.tangent1, c.tangent2);
      c.friction = combine_friction(a.material.friction, b.material.friction);
      c.restitution = combine_restitution(a.material.restitution, b.material.restitution);
      c.force_world.setZero();
      warm_start(data_, c);
    }
  }

 private:
  const Model& model_;
  Data& data_;
};

Candidate body_candidate(const Model& model, const Data& data, size_t g) {
  using namespace spatial;
  const Geom& geom = model.geoms[g];
  const auto b = static_cast<size_t>(geom.body);
  const Vec6& v = data.cvel[b];
  const Vec3 centre = data.xgeom[g].pos;
  const double speed = point_velocity(v, centre - data.origin).norm() + ang(v).norm() * bounding_radius(geom.shape);
  return {&geom.shape,
          data.xgeom[g],
          {ContactSide::Kind::body, geom.body, static_cast<int>(g)},
          geom.material,
          speed * model.timestep_s};
}

Candidate object_candidate(const Model& model, const Data& data, size_t i) {
  const Object& o = data.objects[i];
  Pose p;
  p.pos = o.pos;
  p.rot = o.quat.toRotationMatrix();
  const double speed = o.lin_vel.norm() + o.ang_vel.norm() * bounding_radius(o.shape);
  return {&o.shape, p, {ContactSide::Kind::object, static_cast<int>(i), -1}, o.material, speed * model.timestep_s};
}

// Self-collision skips a body's own geoms and its parent's (they touch at the joint by design).
bool adjacent(const Model& model, int b1, int b2) {
  return b1 == b2 || model.bodies[static_cast<size_t>(b1)].parent == b2 ||
         model.bodies[static_cast<size_t>(b2)].parent == b1;
}

}  // namespace

void detect_contacts(const Model& model, Data& data) {
  data.ncon = 0;
  if (!model.features.contacts || !data.collisions.contacts) return;
  Collector collect(model, data);
  static const Shape kPlane = Shape::plane();
  const Candidate ground{&kPlane, ground_pose(model.ground), {}, model.ground.material, 0.0};
  const bool with_ground = model.ground.enabled && data.collisions.ground;
  const bool with_objects = data.collisions.objects;
  const auto ngeom = static_cast<size_t>(model.ngeom);

  for (size_t g = 0; g < ngeom; ++g) {
    const Geom& geom = model.geoms[g];
    const Candidate body = body_candidate(model, data, g);
    if (with_ground && data.collisions.body_ground && geom.collides_with_ground) collect.pair(body, ground);
    if (with_objects && geom.collides_with_objects) {
      for (size_t i = 0; i < kMaxObjects; ++i) {
        if (data.objects[i].active) collect.pair(object_candidate(model, data, i), body);
      }
    }
  }
  for (size_t i = 0; i < kMaxObjects; ++i) {
    if (!data.objects[i].active) continue;
    const Candidate obj = object_candidate(model, data, i);
    if (with_ground) collect.pair(obj, ground);
    for (size_t j = i + 1; j < kMaxObjects; ++j) {
      if (data.objects[j].active) collect.pair(obj, object_candidate(model, data, j));
    }
  }
  if (model.features.self_collision) {
    for (size_t g1 = 0; g1 < ngeom; ++g1) {
      for (size_t g2 = g1 + 1; g2 < ngeom; ++g2) {
        if (adjacent(model, model.geoms[g1].body, model.geoms[g2].body)) continue;
        collect.pair(body_candidate(model, data, g1), body_candidate(model, data, g2));
      }
    }
  }
}

}  // namespace tonus::sim::detail
