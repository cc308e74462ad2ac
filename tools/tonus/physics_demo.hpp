// `tonus physics`: the physics core on its own. The default humanoid stands
// on the ground holding its pose with its drives; a 1 kg cube is dropped on
// its left hand and a ball is thrown at its chest. Prints what happened and
// what it cost, and can export the model as MJCF for MuJoCo's viewer.
#pragma once

#include <string>

namespace tonus::tools {

struct PhysicsDemoOptions {
  double seconds = 3.0;
  double height_m = 1.70;
  double mass_kg = 65.0;
  double hold_hz = 40.0;        // natural frequency of the drives holding the pose
  double ball_speed_mps = 8.0;  // thrown at the chest at t = 1 s
  std::string mjcf_path;        // write the scene as MJCF (empty: no file)
};

// 0 when the scene behaved (no divergence, the cube came to rest carrying its
// weight, the avatar stayed up), 1 otherwise.
int run_physics_demo(const PhysicsDemoOptions& opt);

}  // namespace tonus::tools
