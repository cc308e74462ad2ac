// Energy and momentum of everything that moves (articulation and objects),
// for the conservation checks and the divergence guard.
#include <cstddef>

#include "spatial.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::sim {

Energy energy(const Model& model, const Data& data) {
  Energy e;
  const Vec3 g = model.features.gravity ? model.gravity : Vec3::Zero();
  for (std::size_t i = 0; i < static_cast<std::size_t>(model.nbody); ++i) {
    const spatial::Inertia in{model.bodies[i].mass_kg, data.cinert_h[i], data.cinert_i[i]};
    e.kinetic_j += 0.5 * data.cvel[i].dot(in.apply(data.cvel[i]));
    e.potential_j -= model.bodies[i].mass_kg * g.dot(data.xcom[i]);
  }
  for (int k = 0; k < model.nv; ++k) {  // the armature's own kinetic energy
    const auto ku = static_cast<std::size_t>(k);
    e.kinetic_j +=
        0.5 * model.bodies[static_cast<std::size_t>(model.dof_body[ku])].armature * data.qvel[ku] * data.qvel[ku];
  }
  for (const Object& o : data.objects) {
    if (!o.active) continue;
    const Mat3 r = o.quat.toRotationMatrix();
    const Vec3 wb = r.transpose() * o.ang_vel;
    e.objects_kinetic_j += 0.5 * o.mass_kg * o.lin_vel.squaredNorm() + 0.5 * wb.dot(o.inertia_diag.cwiseProduct(wb));
    e.potential_j -= o.mass_kg * g.dot(o.pos);
  }
  e.kinetic_j += e.objects_kinetic_j;
  return e;
}

Momentum momentum(const Model& model, const Data& data) {
  Momentum m;
  for (std::size_t i = 0; i < static_cast<std::size_t>(model.nbody); ++i) {
    const spatial::Inertia in{model.bodies[i].mass_kg, data.cinert_h[i], data.cinert_i[i]};
    const Vec6 h = in.apply(data.cvel[i]);  // (angular about the origin; linear)
    m.linear += h.tail<3>();
    m.angular += h.head<3>() + data.origin.cross(Vec3(h.tail<3>()));
  }
  for (const Object& o : data.objects) {
    if (!o.active) continue;
    const Mat3 r = o.quat.toRotationMatrix();
    const Mat3 inertia = r * o.inertia_diag.asDiagonal() * r.transpose();
    m.linear += o.mass_kg * o.lin_vel;
    m.angular += inertia * o.ang_vel + o.pos.cross(Vec3(o.mass_kg * o.lin_vel));
  }
  return m;
}

}  // namespace tonus::sim
