// Shared test fixtures for the physics core: models built for the tests and
// a MuJoCo model loaded from our MJCF export (the independent reference).
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <random>
#include <span>
#include <string>

#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/model_builder.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::sim::test {

// The default humanoid with options; fails the test on a build error.
std::unique_ptr<Model> humanoid(const Features& features, Integrator integrator = Integrator::euler,
                                const HumanoidSpec& spec = {});

// Adds a 1 kg, 8 cm cube resting 1 mm above the right hand (at the current
// kinematics); false when the scene has no room.
bool add_cube_on_right_hand(const Model& model, Data& data);

// A MuJoCo model and data, loaded from an MJCF string.
class Mujoco {
 public:
  explicit Mujoco(const std::string& xml);
  ~Mujoco();
  Mujoco(const Mujoco&) = delete;
  Mujoco& operator=(const Mujoco&) = delete;
  [[nodiscard]] bool ok() const { return model_ != nullptr; }
  [[nodiscard]] const std::string& error() const { return error_; }
  mjModel* m() { return model_; }
  mjData* d() { return data_; }

 private:
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::string error_;
};

// A random configuration of the joints (not the root) into `qpos`: ball
// joints rotated by N(0, spread) per axis, hinges inside their range when
// they have one (else N(0, spread)). Seeded, reproducible.
void random_joint_pose(const Model& model, std::span<double> qpos, unsigned seed, double spread);

// Inputs with every drive off (kp = kd = 0), holding nothing.
StepInputs passive_inputs(const Model& model);

// Largest rotation angle between two configurations, joint by joint: the
// angle of q1^-1 q2 for quaternions, |a1 - a2| for hinges, position distance
// for the free root's translation. Convention-free comparison with MuJoCo.
double max_joint_difference(const Model& model, const double* qpos1, const double* qpos2);

}  // namespace tonus::sim::test
