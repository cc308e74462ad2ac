// Model queries and the inputs that start from a model.
#include "tonus/sim/model.hpp"

#include "tonus/sim/inputs.hpp"

namespace tonus::sim {

double Model::total_mass_kg() const {
  double m = 0.0;
  for (int i = 0; i < nbody; ++i) m += bodies[static_cast<std::size_t>(i)].mass_kg;
  return m;
}

int Model::body_index(std::string_view n) const {
  for (int i = 0; i < nbody; ++i) {
    if (bodies[static_cast<std::size_t>(i)].name_view() == n) return i;
  }
  return -1;
}

int Model::first_geom(int body) const {
  for (int g = 0; g < ngeom; ++g) {
    if (geoms[static_cast<std::size_t>(g)].body == body) return g;
  }
  return -1;
}

StepInputs make_inputs(const Model& model) {
  StepInputs in;
  in.target_qpos = model.qpos0;
  in.kp = model.dof_kp;
  in.kd = model.dof_kd;
  for (int i = 0; i < model.nbody; ++i) {
    const auto b = static_cast<std::size_t>(i);
    in.torque_limit_nm[b] = model.bodies[b].drive.torque_limit_nm;
  }
  const Body& root = model.bodies[0];
  if (root.joint == JointType::free) {
    in.root_pos = Vec3(model.qpos0[0], model.qpos0[1], model.qpos0[2]);
    in.root_quat = Quat(model.qpos0[3], model.qpos0[4], model.qpos0[5], model.qpos0[6]);
  } else {
    in.root_pos = root.pos_in_parent;
    in.root_quat = root.quat_in_parent;
  }
  return in;
}

void set_joint_gains(const Model& model, StepInputs& in, int body, double kp, double kd) {
  if (body < 0 || body >= model.nbody) return;
  const Body& b = model.bodies[static_cast<std::size_t>(body)];
  for (int k = b.dof_adr; k < b.dof_adr + b.dof_num; ++k) {
    in.kp[static_cast<std::size_t>(k)] = kp;
    in.kd[static_cast<std::size_t>(k)] = kd;
  }
}

void scale_joint_gains(const Model& model, StepInputs& in, int body, double kp_factor, double kd_factor) {
  if (body < 0 || body >= model.nbody) return;
  const Body& b = model.bodies[static_cast<std::size_t>(body)];
  for (int k = b.dof_adr; k < b.dof_adr + b.dof_num; ++k) {
    in.kp[static_cast<std::size_t>(k)] *= kp_factor;
    in.kd[static_cast<std::size_t>(k)] *= kd_factor;
  }
}

}  // namespace tonus::sim
