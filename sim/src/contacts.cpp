// Collision detection: which shapes touch (or will within a step), turned
// into Contacts between sides (body, object, ground), warm-started from the
// previous step's contacts at the same place.
//
// Broad phase: sweep and prune on x over every shape's bounding box grown by
// what it sweeps in a step (a hundred objects make 5,000 pairs to test; the
// sweep tests only the neighbours), plus one test of each shape against the
// ground plane.
//
// Past the capacity (SolverOptions::max_contacts) the least important points go first: a pair's deepest
// point before its others, then contacts on the avatar before an object on
// the ground before objects between themselves, then depth. So a crowded
// scene keeps at least one point under every pair that touches (nothing
// falls through the floor) and only loses the extra points of a manifold.
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
  p.rot = sim::quat_from_two_vectors(Vec3::UnitZ(), g.normal).toRotationMatrix();
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

std::uint64_t side_key(const ContactSide& s) {
  return (static_cast<std::uint64_t>(s.kind) << 24) | (static_cast<std::uint64_t>(s.index + 1) << 8) |
         static_cast<std::uint64_t>(s.geom + 1);
}

// Contacts between the same two sides (in the same roles) share a key.
std::uint64_t pair_key(const Contact& c) { return (side_key(c.a) << 32) | side_key(c.b); }

// Last step's impulse at (nearly) the same place between the same sides.
void warm_start(const Data& data, Contact& c) {
  constexpr double kMatchDistance = 0.02;  // m
  const std::uint64_t key = pair_key(c);
  const auto* order = data.prev_order.data();
  const auto* end = order + data.prev_ncon;
  const auto* it =
      std::lower_bound(order, end, key, [&](std::uint16_t i, std::uint64_t k) { return data.prev_keys[i] < k; });
  double best = kMatchDistance * kMatchDistance;
  const Contact* match = nullptr;
  for (; it != end && data.prev_keys[*it] == key; ++it) {
    const Contact& p = data.prev_contacts[*it];
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

// How much a contact point matters when room runs out (higher stays).
double priority(const ContactSide& a, const ContactSide& b, bool deepest_of_pair, double dist_m) {
  using K = ContactSide::Kind;
  const bool avatar = a.kind == K::body || b.kind == K::body;
  const bool ground = a.kind == K::ground || b.kind == K::ground;
  const double kind = avatar ? 2.0 : (ground ? 1.0 : 0.0);
  return (deepest_of_pair ? 10.0 : 0.0) + kind - std::clamp(dist_m, -0.5, 0.5);
}

class Collector {
 public:
  Collector(const Model& model, Data& data)
      : model_(model),
        data_(data),
        capacity_(std::clamp(model.solver.max_contacts, 1, static_cast<int>(kMaxContacts))) {}

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
    size_t deepest = 0;
    for (size_t k = 1; k < n; ++k) {
      if (points[k].dist_m < points[deepest].dist_m) deepest = k;
    }
    for (size_t k = 0; k < n; ++k) {
      const double prio = priority(a.side, b.side, k == deepest, points[k].dist_m);
      const int slot = take_slot(prio);
      if (slot < 0) continue;
      Contact& c = data_.contacts[static_cast<size_t>(slot)];
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
      data_.contact_priority[static_cast<size_t>(slot)] = prio;
      if (full_) push_heap();
    }
  }

 private:
  struct Greater {
    const Data* data;
    bool operator()(std::uint16_t x, std::uint16_t y) const {
      const double px = data->contact_priority[x], py = data->contact_priority[y];
      return px != py ? px > py : x > y;  // ties by slot: deterministic
    }
  };
  [[nodiscard]] Greater greater() const { return Greater{&data_}; }
  // A slot for a point of this priority: the next free one, or the least
  // important taken one if this point matters more (then counted as dropped).
  int take_slot(double prio) {
    if (data_.ncon < capacity_) return data_.ncon++;
    ++data_.diag.contact_overflow;
    auto* heap = data_.contact_heap.data();
    if (!full_) {  // first overflow this step: a min-heap of the priorities
      for (int i = 0; i < capacity_; ++i) heap[i] = static_cast<std::uint16_t>(i);
      std::make_heap(heap, heap + capacity_, greater());
      full_ = true;
    }
    if (prio <= data_.contact_priority[heap[0]]) return -1;
    std::pop_heap(heap, heap + capacity_, greater());
    return heap[capacity_ - 1];
  }
  void push_heap() { std::push_heap(data_.contact_heap.data(), data_.contact_heap.data() + capacity_, greater()); }

  const Model& model_;
  Data& data_;
  int capacity_;
  bool full_ = false;
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

// Every shape that may touch another, as a bounding box for sweep and prune.
struct Box {
  double lo[3], hi[3];
  int id;  // geom g, or kMaxGeoms + object slot
};

constexpr int kObjectIds = static_cast<int>(kMaxGeoms);

}  // namespace

void detect_contacts(const Model& model, Data& data) {
  data.ncon = 0;
  if (!model.features.contacts || !data.collisions.contacts) return;
  Collector collect(model, data);
  static const Shape kPlane = Shape::plane();
  const Candidate ground{&kPlane, ground_pose(model.ground), {}, model.ground.material, 0.0};
  const bool with_ground = model.ground.enabled && data.collisions.ground;
  const bool with_objects = data.collisions.objects;
  const bool self = model.features.self_collision;
  const auto ngeom = static_cast<size_t>(model.ngeom);

  std::array<Candidate, kMaxGeoms + kMaxObjects> cand;
  std::array<Box, kMaxGeoms + kMaxObjects> boxes;
  size_t nbox = 0;
  const auto add_box = [&](const Candidate& c, int id) {
    const double r = bounding_radius(*c.shape) + c.sweep_m + 0.5 * model.solver.contact_margin_m;
    Box& b = boxes[nbox++];
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = c.pose.pos(k) - r;
      b.hi[k] = c.pose.pos(k) + r;
    }
    b.id = id;
  };
  for (size_t g = 0; g < ngeom; ++g) {
    const Geom& geom = model.geoms[g];
    cand[g] = body_candidate(model, data, g);
    if (with_ground && data.collisions.body_ground && geom.collides_with_ground) collect.pair(cand[g], ground);
    if ((with_objects && geom.collides_with_objects) || self) add_box(cand[g], static_cast<int>(g));
  }
  for (size_t i = 0; i < kMaxObjects; ++i) {
    if (!data.objects[i].active) continue;
    const size_t at = kMaxGeoms + i;
    cand[at] = object_candidate(model, data, i);
    if (with_ground) collect.pair(cand[at], ground);
    add_box(cand[at], kObjectIds + static_cast<int>(i));
  }

  std::sort(boxes.begin(), boxes.begin() + static_cast<std::ptrdiff_t>(nbox),
            [](const Box& x, const Box& y) { return x.lo[0] != y.lo[0] ? x.lo[0] < y.lo[0] : x.id < y.id; });
  for (size_t i = 0; i < nbox; ++i) {
    for (size_t j = i + 1; j < nbox && boxes[j].lo[0] <= boxes[i].hi[0]; ++j) {
      const Box &x = boxes[i], &y = boxes[j];
      if (x.lo[1] > y.hi[1] || y.lo[1] > x.hi[1] || x.lo[2] > y.hi[2] || y.lo[2] > x.hi[2]) continue;
      // Roles as the pair rules fix them: objects first, lower slot or geom first.
      const int p = std::min(x.id, y.id), q = std::max(x.id, y.id);
      const auto up = static_cast<size_t>(p), uq = static_cast<size_t>(q);
      const bool both_objects = p >= kObjectIds, geom_object = !both_objects && q >= kObjectIds;
      if (geom_object) {
        if (with_objects && model.geoms[up].collides_with_objects) collect.pair(cand[uq], cand[up]);
      } else if (both_objects || (self && !adjacent(model, model.geoms[up].body, model.geoms[uq].body))) {
        collect.pair(cand[up], cand[uq]);
      }
    }
  }
}

void remember_contacts(Data& data) {
  const auto n = static_cast<size_t>(data.ncon);
  for (size_t i = 0; i < n; ++i) {
    data.prev_contacts[i] = data.contacts[i];
    data.prev_keys[i] = pair_key(data.contacts[i]);
    data.prev_order[i] = static_cast<std::uint16_t>(i);
  }
  std::sort(data.prev_order.begin(), data.prev_order.begin() + static_cast<std::ptrdiff_t>(n),
            [&](std::uint16_t x, std::uint16_t y) {
              return data.prev_keys[x] != data.prev_keys[y] ? data.prev_keys[x] < data.prev_keys[y] : x < y;
            });
  data.prev_ncon = data.ncon;
}

}  // namespace tonus::sim::detail
