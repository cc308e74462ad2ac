// Writes a Model (and optionally a Data's objects) as MuJoCo MJCF XML, so the
// same humanoid can be inspected in MuJoCo's viewer and serve as the
// independent reference the tests and benchmarks compare against.
//
// The state layouts match one to one (see model.hpp), so a qpos/qvel of ours
// is a valid qpos/qvel of the exported model. What does not translate
// exactly: MuJoCo's contacts are soft and its ball-joint range is one cone on
// the whole rotation (we write the swing cone), and our implicit PD drives are
// written as joint springs toward the rest pose (MuJoCo's passive stiffness
// and damping), which is the same law only for a rest-pose target.
#pragma once

#include <string>

#include "tonus/sim/data.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::sim {

struct MjcfOptions {
  std::string model_name = "tonus";
  bool integrator_euler = true;        // MuJoCo's semi-implicit Euler, as our step
  bool drives_as_springs = false;      // default drive gains as joint stiffness/damping toward qpos0
  const Data* objects_from = nullptr;  // export this Data's active objects as free bodies
};

std::string to_mjcf(const Model& model, const MjcfOptions& options = {});

}  // namespace tonus::sim
