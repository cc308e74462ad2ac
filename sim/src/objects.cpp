// Virtual objects: slots, validation, and their unconstrained motion.
#include "tonus/sim/objects.hpp"

#include <cmath>
#include <cstddef>

#include "stages.hpp"

namespace tonus::sim {
namespace {

bool finite(double x) { return std::isfinite(x); }

Vec3 principal_inertia(const Shape& s, double m) {
  if (s.type == ShapeType::sphere) return Vec3::Constant(0.4 * m * s.radius_m * s.radius_m);
  const Vec3 e = (2.0 * s.half_extents_m).cwiseAbs2();
  return m / 12.0 * Vec3(e.y() + e.z(), e.x() + e.z(), e.x() + e.y());
}

ObjectError check(const ObjectSpec& spec) {
  if (spec.shape.type != ShapeType::sphere && spec.shape.type != ShapeType::box) return ObjectError::bad_shape;
  if (!shape_is_valid(spec.shape)) return ObjectError::bad_shape;
  if (!finite(spec.mass_kg) || spec.mass_kg <= 0.0 || spec.mass_kg > 1e6) return ObjectError::bad_mass;
  const double qn = spec.quat.norm();
  if (!all_finite(spec.pos) || !finite(qn) || qn < 1e-6) return ObjectError::bad_pose;
  if (!all_finite(spec.lin_vel) || !all_finite(spec.ang_vel)) return ObjectError::bad_velocity;
  const Material& m = spec.material;
  if (!finite(m.friction) || m.friction < 0.0 || !finite(m.restitution) || m.restitution < 0.0 || m.restitution > 1.0) {
    return ObjectError::bad_material;
  }
  return ObjectError::none;
}

}  // namespace

std::string_view to_string(ObjectError e) {
  switch (e) {
    case ObjectError::none: return "none";
    case ObjectError::full: return "no free object slot (kMaxObjects reached)";
    case ObjectError::bad_shape: return "shape must be a sphere or a box with finite positive sizes";
    case ObjectError::bad_mass: return "mass_kg must be finite and in (0, 1e6]";
    case ObjectError::bad_pose: return "pose must be finite with a non-zero quaternion";
    case ObjectError::bad_velocity: return "velocities must be finite";
    case ObjectError::bad_material: return "friction must be >= 0 and restitution in [0, 1]";
  }
  return "unknown";
}

AddObjectResult add_object(Data& data, const ObjectSpec& spec) {
  AddObjectResult r;
  r.error = check(spec);
  if (r.error != ObjectError::none) return r;
  for (std::size_t i = 0; i < kMaxObjects; ++i) {
    Object& o = data.objects[i];
    if (o.active) continue;
    const std::uint32_t generation = o.generation + 1;
    o = Object{};
    o.active = true;
    o.generation = generation;
    o.shape = spec.shape;
    o.mass_kg = spec.mass_kg;
    o.inertia_diag = principal_inertia(spec.shape, spec.mass_kg);
    o.material = spec.material;
    o.pos = spec.pos;
    o.quat = spec.quat.normalized();
    o.lin_vel = spec.lin_vel;
    o.ang_vel = spec.ang_vel;
    r.handle = {static_cast<int>(i), generation};
    return r;
  }
  r.error = ObjectError::full;
  return r;
}

Object* find_object(Data& data, ObjectHandle h) {
  if (h.slot < 0 || static_cast<std::size_t>(h.slot) >= kMaxObjects) return nullptr;
  Object& o = data.objects[static_cast<std::size_t>(h.slot)];
  return o.active && o.generation == h.generation ? &o : nullptr;
}

const Object* find_object(const Data& data, ObjectHandle h) { return find_object(const_cast<Data&>(data), h); }

bool remove_object(Data& data, ObjectHandle h) {
  Object* o = find_object(data, h);
  if (o == nullptr) return false;
  o->active = false;
  return true;
}

int active_object_count(const Data& data) {
  int n = 0;
  for (const Object& o : data.objects) n += o.active ? 1 : 0;
  return n;
}

namespace detail {

void objects_free_velocity(const Model& model, Data& data) {
  const double dt = model.timestep_s;
  const Vec3 g = model.features.gravity ? model.gravity : Vec3::Zero();
  for (std::size_t i = 0; i < kMaxObjects; ++i) {
    const Object& o = data.objects[i];
    if (!o.active) continue;
    const Mat3 r = o.quat.toRotationMatrix();
    data.obj_inv_inertia[i] = r * o.inertia_diag.cwiseInverse().asDiagonal() * r.transpose();
    data.obj_lin_free[i] = o.lin_vel + dt * (g + o.force / o.mass_kg);
    // Gyroscopic torque, implicit (one Newton step in the body frame, as
    // Box2D/Bullet do): explicit Euler would spin up a tumbling box.
    const Vec3 w = r.transpose() * o.ang_vel;
    const Mat3 inertia = o.inertia_diag.asDiagonal();
    const Vec3 residual = dt * w.cross(inertia * w);
    const Mat3 jac = inertia + dt * (skew(w) * inertia - skew(inertia * w));
    data.obj_ang_free[i] = r * (w - jac.partialPivLu().solve(residual));
  }
}

}  // namespace detail
}  // namespace tonus::sim
