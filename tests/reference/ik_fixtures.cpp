#include "ik_fixtures.hpp"

#include <doctest/doctest.h>

#include <random>

#include "tonus/sim/joint_limits.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::reference::test {

using sim::Quat;
using sim::Vec3;

IkRig make_ik_rig(double height_m, int count, const IkOptions& options, bool exact) {
  IkRig rig;
  sim::HumanoidSpec spec;
  spec.height_m = height_m;
  sim::BuildResult truth = sim::build_humanoid(spec);
  REQUIRE(truth);
  rig.truth = std::move(truth.model);
  rig.truth_data = sim::make_data(*rig.truth);
  const auto turn = [](double a, const Vec3& axis) { return Quat(Eigen::AngleAxisd(a, axis)); };
  const auto set = [&](Tracker t, const Vec3& p, const Quat& q) { rig.worn[index(t)] = {p, q, true}; };
  set(Tracker::head, Vec3(0.09, 0.01, 0.08), turn(0.2, Vec3::UnitY()));
  set(Tracker::left_hand, Vec3(0.01, 0.07, -0.025), turn(0.6, Vec3::UnitX()));
  set(Tracker::right_hand, Vec3(0.01, -0.07, -0.025), turn(-0.6, Vec3::UnitX()));
  if (count == 6) {
    set(Tracker::waist, Vec3(-0.11, 0.0, 0.03), turn(3.0, Vec3::UnitZ()));
    set(Tracker::left_foot, Vec3(0.05, 0.01, 0.05), turn(0.4, Vec3::UnitY()));
    set(Tracker::right_foot, Vec3(0.05, -0.01, 0.05), turn(0.4, Vec3::UnitY()));
  }
  const TrackerFrame standing = pose_truth(rig, rig.truth->qpos0, 0.0);
  const CalibrationResult cal = calibrate(standing);
  REQUIRE_MESSAGE(cal.ok(), cal.error);
  rig.calibration = cal.body;
  if (exact) {
    rig.calibration.height_m = height_m;
    rig.calibration.arm_scale = 1.0;
    rig.calibration.offset = rig.worn;
  }
  sim::BuildResult solved = sim::build_humanoid(calibrated_spec(rig.calibration, 65.0));
  REQUIRE(solved);
  rig.solved = std::move(solved.model);
  rig.solved_data = sim::make_data(*rig.solved);
  IkCreated ik = make_ik_model(*rig.solved, rig.calibration, options);
  REQUIRE_MESSAGE(ik.model, ik.error);
  rig.ik = *ik.model;
  return rig;
}

TrackerFrame pose_truth(IkRig& rig, const std::array<double, sim::kMaxQpos>& qpos, double time_s) {
  rig.truth_data->qpos = qpos;
  sim::forward_kinematics(*rig.truth, *rig.truth_data);
  TrackerFrame f;
  f.time_s = time_s;
  for (std::size_t t = 0; t < kTrackerCount; ++t) {
    if (!rig.worn[t].valid) continue;
    const std::size_t b = sim::index(tracked_bone(static_cast<Tracker>(t)));
    f.pose[t] = compose({rig.truth_data->xbody[b].pos, rig.truth_data->xquat[b], true}, rig.worn[t]);
  }
  return f;
}

std::array<Vec3, sim::kBoneCount> solved_joints(IkRig& rig, const std::array<double, sim::kMaxQpos>& qpos) {
  rig.solved_data->qpos = qpos;
  sim::forward_kinematics(*rig.solved, *rig.solved_data);
  std::array<Vec3, sim::kBoneCount> j{};
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) j[b] = rig.solved_data->xbody[b].pos;
  return j;
}

Vec3 bone_target(const IkRig& rig, const TrackerFrame& frame, Tracker t) {
  return compose(frame[t], inverse(rig.calibration.offset[index(t)])).pos_m;
}

std::array<double, sim::kMaxQpos> rest_qpos(const sim::Model& m, const Vec3& root, double yaw_rad) {
  std::array<double, sim::kMaxQpos> q = m.qpos0;
  const Quat r(Eigen::AngleAxisd(yaw_rad, Vec3::UnitZ()));
  q[0] = root.x();
  q[1] = root.y();
  q[2] = root.z();
  q[3] = r.w();
  q[4] = r.x();
  q[5] = r.y();
  q[6] = r.z();
  return q;
}

std::array<double, sim::kMaxQpos> random_pose(const sim::Model& m, std::uint32_t seed, double max_rad,
                                              const Vec3& root) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::array<double, sim::kMaxQpos> q = rest_qpos(m, root, 3.0 * u(rng));
  for (int i = 1; i < m.nbody; ++i) {
    const sim::Body& b = m.bodies[static_cast<std::size_t>(i)];
    const auto a = static_cast<std::size_t>(b.qpos_adr);
    if (b.joint == sim::JointType::hinge) {
      q[a] = b.limit.lower_rad + 0.5 * (u(rng) + 1.0) * (b.limit.upper_rad - b.limit.lower_rad);
    } else if (b.joint == sim::JointType::ball) {
      const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
      const Quat r(Eigen::AngleAxisd(max_rad * u(rng), axis));
      q[a] = r.w();
      q[a + 1] = r.x();
      q[a + 2] = r.y();
      q[a + 3] = r.z();
    }
  }
  sim::clamp_to_limits(m, q);
  return q;
}

}  // namespace tonus::reference::test
