// Shared set-up of the tracker IK tests: a ground-truth humanoid, trackers
// worn on it at fixed offsets (read off sim's forward kinematics, not the
// solver's), and the calibrated solver.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "tonus/host/reference/calibration.hpp"
#include "tonus/host/reference/tracker_ik.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/humanoid.hpp"

namespace tonus::reference::test {

struct IkRig {
  std::unique_ptr<sim::Model> truth;   // the performer
  std::unique_ptr<sim::Model> solved;  // the humanoid the calibration builds
  std::unique_ptr<sim::Data> truth_data, solved_data;
  std::array<TrackerPose, kTrackerCount> worn{};  // bone -> tracker, on the truth
  BodyCalibration calibration;
  std::optional<IkModel> ik;
};

// A performer of `height_m` wearing `count` trackers (3 or 6), calibrated from
// a standing T-pose; `options` for the solver. `exact`: the solver is given
// the truth's own body and tracker offsets instead (the solver alone judged).
IkRig make_ik_rig(double height_m, int count, const IkOptions& options = {}, bool exact = false);

// A random configuration of `m` within its joint ranges: every ball joint
// turned up to `max_rad` about a random axis, hinges anywhere in range, the
// root at `root` facing a random way.
std::array<double, sim::kMaxQpos> random_pose(const sim::Model& m, std::uint32_t seed, double max_rad,
                                              const sim::Vec3& root);

// The truth posed at `qpos`, and the trackers it carries (sim's kinematics).
TrackerFrame pose_truth(IkRig& rig, const std::array<double, sim::kMaxQpos>& qpos, double time_s);

// sim's kinematics of a solved configuration: joint positions.
std::array<sim::Vec3, sim::kBoneCount> solved_joints(IkRig& rig, const std::array<double, sim::kMaxQpos>& qpos);

// The wrist or head joint a tracker sample asks for, through the calibration.
sim::Vec3 bone_target(const IkRig& rig, const TrackerFrame& frame, Tracker t);

// The truth's rest configuration with the root at `root` facing `yaw_rad`.
std::array<double, sim::kMaxQpos> rest_qpos(const sim::Model& m, const sim::Vec3& root, double yaw_rad);

}  // namespace tonus::reference::test
