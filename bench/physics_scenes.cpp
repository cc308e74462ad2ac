// The benchmark scenes: layouts computed from the humanoid's geometry at its
// rest pose, so they stay valid if the body's proportions change.
#include "physics_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/mjcf.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::bench {
namespace {

using sim::Bone;
using sim::Vec3;
using std::size_t;

constexpr double kPi = 3.14159265358979323846;
constexpr double kBoxHalf = 0.04;   // pile boxes and the static scene's cube: 8 cm
constexpr double kGap = 0.01;       // between pile boxes, and between boxes and the feet
constexpr double kDropGap = 0.001;  // objects start this far above what they rest on
constexpr double kShowerRadius = 0.04;
constexpr double kShowerBottomM = 2.0, kShowerTopM = 3.5, kShowerHalfWidthM = 0.4;
constexpr int kShowerGrid = 5;  // balls per row of a drop layer: 5 x 5 per layer

// A deterministic hash (splitmix64) turned into a number in [-1, 1).
double jitter(std::uint64_t key) {
  std::uint64_t z = key + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  z ^= z >> 31U;
  return static_cast<double>(z >> 11U) * 0x1.0p-52 - 1.0;
}

const sim::Pose& geom_pose(const sim::Model& m, const sim::Data& d, Bone b) {
  return d.xgeom[static_cast<size_t>(m.first_geom(static_cast<int>(sim::index(b))))];
}
const sim::Shape& geom_shape(const sim::Model& m, Bone b) {
  return m.geoms[static_cast<size_t>(m.first_geom(static_cast<int>(sim::index(b))))].shape;
}

// The lowest point of a geom and the points of its outline that lie furthest
// out in the horizontal plane (corners, or ends pushed out by the radius),
// reported to `visit(xy, extra_radius)`.
template <class Fn>
double outline(const sim::Geom& g, const sim::Pose& x, Fn&& visit) {
  const sim::Shape& s = g.shape;
  double lowest = 1e9;
  if (s.type == sim::ShapeType::box) {
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner(((c & 1) != 0 ? 1 : -1) * s.half_extents_m.x(), ((c & 2) != 0 ? 1 : -1) * s.half_extents_m.y(),
                        ((c & 4) != 0 ? 1 : -1) * s.half_extents_m.z());
      const Vec3 p = x.apply(corner);
      visit(p, 0.0);
      lowest = std::min(lowest, p.z());
    }
  } else {  // sphere (half_length 0) or capsule: its two ends, grown by the radius
    for (const double end : {-s.half_length_m, s.half_length_m}) {
      const Vec3 p = x.apply(Vec3(0.0, 0.0, end));
      visit(p, s.radius_m);
      lowest = std::min(lowest, p.z() - s.radius_m);
    }
  }
  return lowest;
}

// Adds an object; on failure names the scene and the object in `error`.
bool add(sim::Data& d, const sim::ObjectSpec& o, const SceneSpec& spec, const char* what, int k, std::string& error,
         int* slot = nullptr) {
  const sim::AddObjectResult r = sim::add_object(d, o);
  if (r.error != sim::ObjectError::none) {
    error = spec.name + ": add_object(" + what + " " + std::to_string(k) + "): " + std::string(sim::to_string(r.error));
    return false;
  }
  if (slot != nullptr) *slot = r.handle.slot;
  return true;
}

bool add_cube_on_hand(const sim::Model& m, sim::Data& d, const SceneSpec& spec, std::string& error) {
  sim::ObjectSpec cube;
  cube.shape = sim::Shape::box(Vec3::Constant(kBoxHalf));
  cube.mass_kg = 1.0;
  cube.pos = geom_pose(m, d, Bone::LeftHand).pos +
             Vec3(0, 0, geom_shape(m, Bone::LeftHand).half_extents_m.z() + kBoxHalf + 0.002);
  return add(d, cube, spec, "cube", 0, error);
}

// The ball starts 1 m behind the chest, aimed so that gravity brings it to
// chest height as it reaches the chest's surface. Behind, not in front: the
// statue's heels are 6 cm behind its ankles and its toes 20 cm in front, and
// throws from the front tip it back over its heels within five throws (in
// MuJoCo too), while from behind it rocks on its toes and stands.
Teleport ball_throw(const sim::Model& m, const sim::Data& d, double radius) {
  constexpr double kSpeed = 6.0, kDistance = 1.0;
  const Vec3 chest = geom_pose(m, d, Bone::Chest).pos;
  const double travel = kDistance - geom_shape(m, Bone::Chest).radius_m - radius;
  const double t = travel / kSpeed;
  Teleport start;
  start.pos = chest - Vec3(kDistance, 0.0, 0.0);
  start.lin_vel = Vec3(kSpeed, 0.0, 0.5 * -m.gravity.z() * t);
  return start;
}

bool build_pile(const sim::Model& m, sim::Data& d, const SceneSpec& spec, std::string& error) {
  sim::ObjectSpec box;
  box.shape = sim::Shape::box(Vec3::Constant(kBoxHalf));
  box.mass_kg = 0.5;
  const int n = spec.count;
  int k = 0;  // boxes placed

  // On the hands (level in the T-pose): one centred, or two side by side
  // along the hand with a gap, per hand.
  const int on_hands = std::min(4, n / 5);
  for (const Bone hand : {Bone::LeftHand, Bone::RightHand}) {
    const int here = on_hands / 2 + (hand == Bone::LeftHand ? on_hands % 2 : 0);
    const sim::Pose& x = geom_pose(m, d, hand);
    const double top = geom_shape(m, hand).half_extents_m.z();
    for (int j = 0; j < here; ++j) {
      const double along = here == 1 ? 0.0 : (j == 0 ? 1.0 : -1.0) * (kBoxHalf + kGap / 2);
      box.pos = x.apply(Vec3(0.0, along, top + kBoxHalf + kDropGap));
      box.quat = sim::Quat(x.rot);
      if (!add(d, box, spec, "box", k++, error)) return false;
    }
  }

  // The rest in stacks of two on a circle around the feet, each box facing the
  // centre. The circle clears everything low of the body (feet, toes, shins)
  // by kGap, and is wide enough that neighbouring stacks' inner edges are kGap apart.
  const int stacks = (n - k + 1) / 2;
  if (stacks == 0) return true;
  constexpr double kStackTop = 4 * kBoxHalf + 2 * kDropGap;
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  const auto low_geoms = [&](auto&& visit) {
    for (size_t g = 0; g < static_cast<size_t>(m.ngeom); ++g) {
      bool low = outline(m.geoms[g], d.xgeom[g], [](const Vec3&, double) {}) < kStackTop + kGap;
      if (low) outline(m.geoms[g], d.xgeom[g], visit);
    }
  };
  low_geoms([&](const Vec3& p, double r) {
    lo = lo.cwiseMin(p - Vec3::Constant(r));
    hi = hi.cwiseMax(p + Vec3::Constant(r));
  });
  const Vec3 c(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), 0.0);
  double reach = 0.0;
  low_geoms([&](const Vec3& p, double r) { reach = std::max(reach, (p - c).head<2>().norm() + r); });
  const double clear = reach + kGap + kBoxHalf;
  const double packed = stacks > 1 ? kBoxHalf + (kBoxHalf + kGap / 2) / std::sin(kPi / stacks) : 0.0;
  const double radius = std::max(clear, packed);
  for (int s = 0; s < stacks; ++s) {
    const double phi = 2.0 * kPi * s / stacks;
    box.quat = sim::Quat(Eigen::AngleAxisd(phi, Vec3::UnitZ()));
    for (int level = 0; level < 2 && k < n; ++level) {
      box.pos = c + Vec3(radius * std::cos(phi), radius * std::sin(phi),
                         kBoxHalf + kDropGap + level * (2 * kBoxHalf + kDropGap));
      if (!add(d, box, spec, "box", k++, error)) return false;
    }
  }
  return true;
}

bool build_shower(sim::Data& d, Schedule& schedule, const SceneSpec& spec, std::string& error) {
  sim::ObjectSpec ball;
  ball.shape = sim::Shape::sphere(kShowerRadius);
  ball.mass_kg = 0.1;
  ball.material.restitution = 0.3;
  int first = 0;
  for (int k = 0; k < spec.count; ++k) {
    const Teleport t = Schedule::drops(spec.count, 0).drop(k, 0);
    ball.pos = t.pos;
    int slot = -1;
    if (!add(d, ball, spec, "ball", k, error, &slot)) return false;
    if (k == 0) first = slot;
    if (slot != first + k) {  // the schedule finds ball k at first + k
      error = spec.name + ": object slots are not consecutive";
      return false;
    }
  }
  schedule = Schedule::drops(spec.count, first);
  return true;
}

}  // namespace

std::vector<SceneSpec> benchmark_scenes() {
  return {{"static", SceneKind::statue, 0, 500},
          {"lively", SceneKind::lively, 0, 500},
          {"pile20", SceneKind::pile, 20, 1000},
          {"pile50", SceneKind::pile, 50, 1000},
          {"shower100", SceneKind::shower, 100, 1500}};
}

SceneSpec pile_scene(int boxes) { return {"boxes" + std::to_string(boxes), SceneKind::pile, boxes, 1000}; }

Schedule Schedule::throws(const Teleport& start) {
  Schedule s;
  s.kind_ = SceneKind::lively;
  s.throw_ = start;
  return s;
}

Schedule Schedule::drops(int count, int first_slot) {
  Schedule s;
  s.kind_ = SceneKind::shower;
  s.count_ = count;
  s.first_slot_ = first_slot;
  return s;
}

Teleport Schedule::drop(int k, std::int64_t n) const {
  // Layers of 5 x 5 cells; odd layers are shifted by half a cell, so a ball of
  // the top layer falling past a freshly dropped one of the bottom layer (the
  // only pair whose drops come in that order soon enough) misses it.
  const int per_layer = kShowerGrid * kShowerGrid;
  const int layers = std::max(1, (count_ + per_layer - 1) / per_layer);
  const int layer = k / per_layer, i = k % kShowerGrid, j = (k / kShowerGrid) % kShowerGrid;
  const double cell = 2.0 * kShowerHalfWidthM / (kShowerGrid + 0.5);
  const double shift = (layer % 2) * 0.5 * cell;
  const double height = (kShowerTopM - kShowerBottomM) / layers;
  const auto key = (static_cast<std::uint64_t>(k) << 32U) ^ static_cast<std::uint64_t>(n) * 3U;
  constexpr double kJitter = 0.005;  // keeps shifted layers' balls 8.9 cm apart
  Teleport t;
  t.slot = first_slot_ + k;
  t.pos = Vec3(-kShowerHalfWidthM + cell * (i + 0.5) + shift + kJitter * jitter(key),
               -kShowerHalfWidthM + cell * (j + 0.5) + shift + kJitter * jitter(key + 1),
               kShowerBottomM + height * (layer + 0.5) + 0.25 * height * jitter(key + 2));
  return t;
}

std::unique_ptr<sim::Model> standing_humanoid() {
  sim::HumanoidSpec spec;
  spec.drive_frequency_hz = 40.0;
  sim::BuildResult r = sim::build_humanoid(spec);
  if (!r) {
    std::fprintf(stderr, "tonus-bench-physics: %s\n", r.error.c_str());
    std::exit(1);
  }
  return std::move(r.model);
}

void TonusScene::put_back() {
  schedule.at(next_step, [this](const Teleport& t) {
    sim::Object& o = data->objects[static_cast<size_t>(t.slot)];
    o.pos = t.pos;
    o.quat = t.quat;
    o.lin_vel = t.lin_vel;
    o.ang_vel = Vec3::Zero();
  });
}

void TonusScene::advance() {
  put_back();
  sim::step(*model, *data, inputs);
  ++next_step;
}

TonusScene make_scene(const SceneSpec& spec) {
  TonusScene s;
  s.spec = spec;
  s.model = standing_humanoid();
  s.data = sim::make_data(*s.model);
  s.inputs = sim::make_inputs(*s.model);
  const sim::Model& m = *s.model;
  sim::Data& d = *s.data;
  bool ok = true;
  switch (spec.kind) {
    case SceneKind::statue: ok = add_cube_on_hand(m, d, spec, s.error); break;
    case SceneKind::lively: {
      ok = add_cube_on_hand(m, d, spec, s.error);
      constexpr double kRadius = 0.06;
      const Teleport start = ball_throw(m, d, kRadius);
      sim::ObjectSpec ball;
      ball.shape = sim::Shape::sphere(kRadius);
      ball.mass_kg = 0.4;
      ball.material.restitution = 0.5;
      ball.pos = start.pos;
      ball.lin_vel = start.lin_vel;
      Teleport t = start;
      ok = ok && add(d, ball, spec, "ball", 0, s.error, &t.slot);
      s.schedule = Schedule::throws(t);
      break;
    }
    case SceneKind::pile: ok = build_pile(m, d, spec, s.error); break;
    case SceneKind::shower: ok = build_shower(d, s.schedule, spec, s.error); break;
  }
  if (!ok) return s;
  sim::MjcfOptions opts;
  opts.drives_as_springs = true;
  opts.objects_from = s.data.get();
  s.mjcf = sim::to_mjcf(m, opts);
  return s;
}

}  // namespace tonus::bench
