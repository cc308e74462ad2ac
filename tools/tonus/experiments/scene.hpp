// What the experiments share: the humanoid, held poses built joint by joint,
// the reference's forward kinematics, and a controller made for them.
#pragma once

#include <memory>
#include <string>

#include "tonus/host/avatar/controller.hpp"
#include "tonus/sim/humanoid.hpp"

namespace tonus::experiments {

// The default humanoid (1.70 m, 65 kg), drives and limits as sim/ builds them.
std::unique_ptr<sim::Model> humanoid_model(std::string& error);

// A pose: the rest pose with some joints turned (ball joints by a rotation
// in their rest frame, hinges by an angle).
class Pose {
 public:
  explicit Pose(const sim::Model& m);
  Pose& ball(sim::Bone b, const sim::Quat& q);
  Pose& hinge(sim::Bone b, double angle_rad);
  [[nodiscard]] const avatar::ReferencePose& reference() const { return ref_; }

 private:
  const sim::Model* m_;
  avatar::ReferencePose ref_;
};

// The paper's held pose: right upper arm lowered 1 rad from the T-pose,
// elbow at 90 degrees so the forearm points forward, the wrist's twist
// levelling the hand (its broad face up); left arm lowered by the side.
avatar::ReferencePose forearm_forward_pose(const sim::Model& m);

// Standing with both arms lowered by the sides (1.3 rad below the T-pose).
avatar::ReferencePose arms_down_pose(const sim::Model& m);

// World frames of a configuration (forward kinematics on a scratch Data).
class Kinematics {
 public:
  explicit Kinematics(const sim::Model& m);
  const sim::Data& at(const std::array<double, sim::kMaxQpos>& qpos);

 private:
  const sim::Model* m_;
  std::unique_ptr<sim::Data> d_;
};

// Centre of a bone's first shape in a Data (the palm's centre for a hand).
sim::Vec3 shape_centre(const sim::Model& m, const sim::Data& d, sim::Bone b);

}  // namespace tonus::experiments
