// Writing a correction back into BVH (apply_correction): the angles it writes
// stay continuous where the hips turn through +-180 degrees or pass near the
// gimbal lock of their channel order, uncorrected frames keep their
// rotations, and the change figures count only what changed.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "balance_fixtures.hpp"
#include "tonus/host/balance/apply.hpp"
#include "tonus/host/motion/kinematics.hpp"
#include "tonus/sim/human_bones.hpp"

using namespace tonus::balance;
namespace motion = tonus::motion;
using tonus::sim::Bone;

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The first `frames` frames of a clip with the hips turned about the file's
// vertical (Y) axis, by `yaw_from` degrees at frame 0 rising `yaw_step` per
// frame, written as principal angles the way most exporters write them (the
// input's own channels wrap and flip) or continuous (each frame's angles
// nearest the previous frame's).
motion::Clip turned(const test::Loaded& l, std::size_t frames, double yaw_from, double yaw_step, bool principal) {
  motion::Clip clip = l.clip;
  clip.frame_count = frames;
  clip.values.resize(frames * clip.channel_count());
  const auto hips = static_cast<std::size_t>(l.mapping.map.joint[tonus::sim::index(Bone::Hips)]);
  const motion::EulerOrder order = *motion::rotation_order(clip.joints[hips]);
  const std::size_t column = motion::channel_columns(clip)[hips];
  std::vector<std::size_t> rotation_columns;
  for (std::size_t c = 0; c < clip.joints[hips].channels.size(); ++c) {
    if (motion::is_rotation(clip.joints[hips].channels[c])) rotation_columns.push_back(column + c);
  }
  for (std::size_t f = 0; f < frames; ++f) {
    const std::vector<motion::JointPose> poses = motion::forward_kinematics(clip, f);
    const int parent = clip.joints[hips].parent;
    const Quat parent_rotation = parent >= 0 ? poses[static_cast<std::size_t>(parent)].rotation : Quat::Identity();
    const double yaw = yaw_from + yaw_step * static_cast<double>(f);
    const Quat global = Quat(Eigen::AngleAxisd(yaw * kDegree, Vec3::UnitY())) * poses[hips].rotation;
    const Quat local = parent_rotation.conjugate() * global;
    const std::span<const double> previous = clip.frame(f > 0 ? f - 1 : 0);
    const motion::EulerAngles a =
        principal || f == 0
            ? motion::euler_from_quaternion(local, order)
            : motion::euler_from_quaternion_near(
                  local, order,
                  {previous[rotation_columns[0]], previous[rotation_columns[1]], previous[rotation_columns[2]]});
    for (std::size_t i = 0; i < 3; ++i) clip.frame(f)[rotation_columns[i]] = a.at(i);
  }
  return clip;
}

std::size_t total(const std::vector<std::size_t>& jumps) {
  std::size_t n = 0;
  for (const std::size_t j : jumps) n += j;
  return n;
}

void check_written(const std::string& name, const std::string& path, std::size_t frames, double yaw_from,
                   double yaw_step, bool principal) {
  CAPTURE(name);
  const test::Loaded source = test::load(path);
  const motion::Clip clip = turned(source, frames, yaw_from, yaw_step, principal);
  const MapResult mapping = map_skeleton(clip);
  REQUIRE(mapping.ok());
  ConvertOptions same_unit;
  same_unit.metres_per_unit = source.conversion.geometry.metres_per_unit;
  const Conversion conv = convert_motion(clip, mapping, same_unit);
  REQUIRE_MESSAGE(conv.ok(), conv.error);
  // A constant small correction, with an uncorrected stretch in the middle:
  // the writing must stay continuous into and out of it.
  const std::size_t gap_from = frames / 3, gap_to = 2 * frames / 3;
  std::vector<Vec3> correction(frames, Vec3::Zero());
  for (std::size_t f = conv.motion.first_frame; f < frames; ++f) {
    if (f < gap_from || f >= gap_to) correction[f] = Vec3(0.06, -0.05, 0.04);
  }
  const AppliedCorrection applied = apply_correction(clip, conv.geometry, conv.motion, correction);
  REQUIRE_MESSAGE(applied.ok(), applied.error);
  const motion::ReadResult back = motion::parse_bvh(motion::write_bvh(applied.clip, 6));
  REQUIRE(back.ok());
  const std::vector<std::size_t> input_jumps = test::rotation_jumps(clip);
  const std::vector<std::size_t> written_jumps = test::rotation_jumps(back.clip);
  // The joints the writer sets have none; the others keep the input's angles
  // (the Bandai clips have jumps of their own, in the spine and arms).
  std::vector<bool> written_joint(clip.joints.size(), false);
  for (const Bone b : {Bone::Hips, Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot, Bone::RightUpperLeg,
                       Bone::RightLowerLeg, Bone::RightFoot}) {
    written_joint[static_cast<std::size_t>(mapping.map.joint[tonus::sim::index(b)])] = true;
  }
  const std::vector<std::size_t> columns = motion::channel_columns(clip);
  std::size_t input_in_written = 0;
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    for (std::size_t c = columns[j]; c < columns[j + 1]; ++c) {
      if (written_joint[j]) input_in_written += input_jumps[c];
      CHECK_MESSAGE(written_jumps[c] == (written_joint[j] ? 0 : input_jumps[c]),
                    test::column_name(clip, c)
                        << ": " << input_jumps[c] << " jumps in the input, " << written_jumps[c] << " written");
    }
  }
  MESSAGE(name << ": Euler jumps over 90 degrees between frames: " << total(input_jumps) << " in the input ("
               << input_in_written << " in the joints written), " << total(written_jumps) << " written");
  if (principal) CHECK(input_in_written > 0);  // the input does wrap or flip there
  // The change figures: the hips turn by the correction itself (their parent
  // is the file's frame or a static dummy), and nothing counts but the seven
  // joints written at the corrected frames.
  std::size_t corrected = 0;
  for (const Vec3& c : correction) corrected += c.norm() != 0.0 ? 1U : 0U;
  CHECK(applied.changed_samples > corrected);
  CHECK(applied.changed_samples <= 7 * corrected);
  REQUIRE(applied.largest_change.size() == 7);
  for (const JointChange& c : applied.largest_change) {
    CHECK_MESSAGE(written_joint[*motion::find_joint(clip, c.joint)], c.joint);
    CHECK(correction[c.frame].norm() != 0.0);
    if (c.bone == "Hips") CHECK(c.max_rad == doctest::Approx(correction[c.frame].norm()).epsilon(1e-9));
  }
  // Only the angles' representation moved: uncorrected frames keep every
  // joint's rotation and position, corrected ones their feet.
  CHECK(applied.max_foot_displacement_m < 1e-9);
  std::vector<motion::JointPose> before, after;
  for (std::size_t f = 0; f < frames; ++f) {
    if (correction[f].norm() != 0.0) continue;
    REQUIRE(motion::forward_kinematics(clip, f, before));
    REQUIRE(motion::forward_kinematics(applied.clip, f, after));
    for (std::size_t j = 0; j < before.size(); ++j) {
      CHECK(after[j].rotation.angularDistance(before[j].rotation) < 1e-12);
      CHECK((after[j].position - before[j].position).norm() < 1e-9);
    }
  }
}

void check_continuous(const std::string& name, const std::string& path, std::size_t frames, double yaw_from,
                      double yaw_step) {
  for (const bool principal : {true, false}) {
    check_written(name + (principal ? ", principal angles" : ", continuous angles"), path, frames, yaw_from, yaw_step,
                  principal);
  }
}

}  // namespace

TEST_CASE("balance: the written angles stay continuous where the hips turn through +-180 degrees") {
  // Bandai: Hips "Zrotation Xrotation Yrotation", the yaw is the third angle.
  check_continuous("Bandai walk", test::shared_clip("dataset-1_walk_normal_001.bvh"), 60, 150.0, 1.0);
  // CMU: Hips "Zrotation Yrotation Xrotation", the yaw is the middle angle and
  // the first and third flip between +-180 as it passes 180.
  check_continuous("CMU walk", test::bundled_clip("cmu_02_walk.bvh"), 121, 150.0, 0.5);
}

TEST_CASE("balance: the written angles stay continuous where the hips pass near gimbal lock") {
  // CMU: the middle angle (the yaw) passes 90 degrees.
  check_continuous("CMU walk", test::bundled_clip("cmu_02_walk.bvh"), 121, 60.0, 0.5);
}
