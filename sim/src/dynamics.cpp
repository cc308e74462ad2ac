// Recursive Newton-Euler (inverse dynamics, bias forces), the composite rigid
// body algorithm (joint-space inertia) and contact-free forward dynamics.
#include <algorithm>
#include <cstddef>

#include "ltdl.hpp"
#include "spatial.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::sim {
namespace {

spatial::Inertia body_inertia(const Model& model, const Data& data, std::size_t i) {
  return {model.bodies[i].mass_kg, data.cinert_h[i], data.cinert_i[i]};
}

}  // namespace

void inverse_dynamics(const Model& model, Data& data, std::span<const double> qacc, std::span<double> tau) {
  using namespace spatial;
  const auto nbody = static_cast<std::size_t>(model.nbody);
  // Gravity enters as a fictitious upward acceleration of the world.
  const Vec6 a_world = make(Vec3::Zero(), model.features.gravity ? Vec3(-model.gravity) : Vec3::Zero());
  std::array<Vec6, kMaxBodies> acc;
  std::array<Vec6, kMaxBodies> force;
  for (std::size_t i = 0; i < nbody; ++i) {
    const Body& b = model.bodies[i];
    Vec6 a = b.parent >= 0 ? acc[static_cast<std::size_t>(b.parent)] : a_world;
    for (int k = 0; k < b.dof_num; ++k) {
      const auto d = static_cast<std::size_t>(b.dof_adr) + static_cast<std::size_t>(k);
      a += data.cdof_dot[d] * data.qvel[d] + data.cdof[d] * qacc[d];
    }
    acc[i] = a;
    const Inertia in = body_inertia(model, data, i);
    force[i] = in.apply(a) + cross_force(data.cvel[i], in.apply(data.cvel[i]));
  }
  for (std::size_t i = nbody; i-- > 0;) {
    const Body& b = model.bodies[i];
    for (int k = 0; k < b.dof_num; ++k) {
      const auto d = static_cast<std::size_t>(b.dof_adr) + static_cast<std::size_t>(k);
      tau[d] = data.cdof[d].dot(force[i]);
    }
    if (b.parent >= 0) force[static_cast<std::size_t>(b.parent)] += force[i];
  }
}

void mass_matrix(const Model& model, Data& data) {
  using namespace spatial;
  const int nv = model.nv;
  const auto nbody = static_cast<std::size_t>(model.nbody);
  std::array<Inertia, kMaxBodies> composite;
  for (std::size_t i = 0; i < nbody; ++i) composite[i] = body_inertia(model, data, i);
  for (std::size_t i = nbody; i-- > 1;) {
    const auto p = static_cast<std::size_t>(model.bodies[i].parent);
    composite[p].m += composite[i].m;
    composite[p].h += composite[i].h;
    composite[p].i += composite[i].i;
  }
  for (int k = 0; k < nv; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const Vec6 f = composite[static_cast<std::size_t>(model.dof_body[ku])].apply(data.cdof[ku]);
    for (int j = k; j >= 0; j = model.dof_parent[static_cast<std::size_t>(j)]) {
      data.mass[ku * static_cast<std::size_t>(nv) + static_cast<std::size_t>(j)] =
          data.cdof[static_cast<std::size_t>(j)].dot(f);
    }
    data.mass[ku * static_cast<std::size_t>(nv) + ku] +=
        model.bodies[static_cast<std::size_t>(model.dof_body[ku])].armature;
  }
}

void forward_dynamics(const Model& model, Data& data, std::span<const double> tau, std::span<double> qacc) {
  const int nv = model.nv;
  mass_matrix(model, data);
  std::array<double, kMaxDofs> zero{};
  inverse_dynamics(model, data, zero, data.bias);
  std::copy_n(data.mass.begin(), nv * nv, data.factor.begin());
  ltdl::factor(data.factor, nv, model.dof_parent, 0);
  for (int k = 0; k < nv; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    qacc[ku] = tau[ku] - data.bias[ku];
  }
  ltdl::solve(data.factor, nv, model.dof_parent, 0, qacc.first(static_cast<std::size_t>(nv)));
}

}  // namespace tonus::sim
