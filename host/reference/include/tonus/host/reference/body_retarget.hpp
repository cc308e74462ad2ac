// Full-body retargeting of streamed bone rotations onto the humanoid, one
// frame at a time: what the VMC protocol's /VMC/Ext/Bone/Pos and
// /VMC/Ext/Root/Pos carry (per HumanBodyBones bone its local rotation, plus
// the root's pose), or a BVH frame through balance::map_skeleton. The input
// is already in the internal frame (right-handed, Z up, metres, the sender's
// floor at z = 0); converting from Unity's left-handed Y-up frame is the VMC
// boundary's job.
//
// Method. Each source bone's world rotation W_i is built from the local
// rotations, and its turn from its own rest, D_i = W_i * W_i_rest^-1 (so the
// sender's bone-axis conventions do not matter). The humanoid's bone is given
// D_i * A_i, where A_i aligns the rest poses: the least turn from the
// humanoid's rest bone direction onto the source's (a T or an A pose, any
// bone lengths); the pelvis by its hip line and spine; the feet neutral with
// the shank, turned about it to the source foot's heading (the ankle-to-ball
// slope is a skeleton's design, not a pose); shoulders (CMU's start at the
// spine), toes, head and hands as their parent. The rest must be a human
// pose: a rest with every bone along one axis (Bandai Namco's BVH) leaves
// twists arbitrary. Elbows and knees (hinges) take the angle that points the
// forearm or shank along the source's, the upper bone twisted so the hinge
// axis is normal to the limb's plane (near straight: the source's own twist),
// and what a clamped hinge cannot do turned into the upper bone so the wrist
// or ankle still points where the source's does. Every joint is clamped into
// the model's limits (sim::clamp_ball, sim::clamp_hinge), children matched
// after their parent's clamp. The root: the source's mid-hip point scaled by
// the ratio of leg lengths (hip to ankle: the hip heights over the ankles of
// a straight standing rest), shifted once so the source's rest, standing on
// its floor, stands the humanoid's feet on z = 0. Every quaternion is kept in the
// hemisphere of the previous frame's.
//
// Model / data split: BodyRetarget is immutable after create() and may be
// shared; BodyRetargetState is one stream's memory (last valid inputs, the
// previous output). solve() allocates nothing, never throws, and never
// writes a non-finite value.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "tonus/sim/capacity.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference {

// The sender's skeleton at rest. A bone's parent is its nearest present
// ancestor (HumanBodyBones order): Neck under Spine when Chest is absent.
struct SourceSkeleton {
  std::array<bool, sim::kBoneCount> present{};
  // Rest offset of the bone's joint from its parent's joint, in the parent's
  // rest frame, m. Hips: the root's rest position in the sender's world,
  // standing on the floor (z = 0), as sim::HumanoidSpec::bone_offsets.
  std::array<sim::Vec3, sim::kBoneCount> offset{};
  // Rest local rotation, relative to the parent's frame (Unity's
  // localRotation at rest); Hips: its world rotation at rest.
  std::array<sim::Quat, sim::kBoneCount> rest_rotation{};

  SourceSkeleton() { rest_rotation.fill(sim::Quat::Identity()); }
};

// The humanoid's own rest (a T-pose, every bone present, identity rotations):
// a source that needs no alignment.
SourceSkeleton skeleton_of(const sim::Model& humanoid);

// An A-pose variant of a skeleton: both upper arms lowered by
// `arms_down_rad` (about the forward axis, through their rest rotations),
// arm segments (upper arm, forearm) scaled by `arm_scale`, leg segments
// (thigh, shank) by `leg_scale`, the root raised or lowered so it still
// stands on z = 0. Meant for skeleton_of's result (T-pose, legs straight down).
SourceSkeleton a_pose_variant(const SourceSkeleton& t_pose, double arms_down_rad, double arm_scale, double leg_scale);

// One frame as the sender gives it.
struct BodySample {
  std::array<bool, sim::kBoneCount> present{};
  // Local rotation relative to the parent's frame (as SourceSkeleton's
  // parents), unit; Hips' entry is ignored (root_rotation is used).
  std::array<sim::Quat, sim::kBoneCount> local{};
  bool root_present = false;
  sim::Vec3 root_position = sim::Vec3::Zero();      // Hips joint, world, m
  sim::Quat root_rotation = sim::Quat::Identity();  // Hips, world

  BodySample() { local.fill(sim::Quat::Identity()); }
};

struct BodyRetargetOptions {
  double unit_tolerance = 0.01;      // a quaternion whose norm is further than this from 1 is refused
  double max_root_distance_m = 1e3;  // a root farther than this from the origin is refused
  // A bone (or root) absent from a sample keeps its last valid value (as a
  // VMC receiver's transforms do); false: its rest.
  bool missing_keeps_last = true;
};

// What one solve() did. Bit i of a mask is sim::Bone i.
struct BodyStatus {
  bool written = false;  // false: qpos_out shorter than the model's nq, nothing written
  int clamped = 0;       // joints moved into their limits
  std::uint32_t clamped_bones = 0;
  std::uint32_t missing_bones = 0;  // skeleton bones absent from the sample
  std::uint32_t invalid_bones = 0;  // rotations not finite or not unit: the last valid kept
  bool root_missing = false;
  bool root_position_invalid = false;  // not finite or beyond max_root_distance_m: the last valid kept
  bool root_rotation_invalid = false;
  bool fallback = false;  // the result was not finite (not expected): the previous output written

  [[nodiscard]] bool input_valid() const {
    return invalid_bones == 0 && !root_position_invalid && !root_rotation_invalid;
  }
};

// One stream's memory. Default-constructed (or reset()) before the first frame.
struct BodyRetargetState {
  bool started = false;
  std::array<sim::Quat, sim::kBoneCount> last_local{};
  sim::Vec3 last_root_position = sim::Vec3::Zero();
  sim::Quat last_root_rotation = sim::Quat::Identity();
  std::array<double, sim::kMaxQpos> previous{};  // the last output (hemisphere continuity, fallback)

  void reset() { started = false; }
};

struct BodyRetargetBuild;

class BodyRetarget {
 public:
  // Checks the model (sim::build_humanoid's, any height) and the skeleton
  // (Hips, legs to the feet, arms to the hands, and the neck or the head
  // present; finite offsets and unit rotations; legs with a length) and
  // resolves the alignment. `humanoid` must outlive the result.
  static BodyRetargetBuild create(const sim::Model& humanoid, const SourceSkeleton& source,
                                  const BodyRetargetOptions& options = {});

  // One frame into qpos_out (the model's layout, nq entries). No allocation,
  // no exception, every value written finite.
  BodyStatus solve(const BodySample& sample, BodyRetargetState& state, std::span<double> qpos_out) const;

  [[nodiscard]] const sim::Model& model() const { return *model_; }
  [[nodiscard]] double scale() const { return scale_; }               // humanoid / source hip height over the ankles
  [[nodiscard]] double height_offset_m() const { return z_offset_; }  // added to the scaled root height
  // The rest alignment of a bone (A_i, world): the humanoid's rest bone turned
  // into the source's rest pose.
  [[nodiscard]] const sim::Quat& alignment(sim::Bone b) const { return align_[sim::index(b)]; }

 private:
  BodyRetarget() = default;

  const sim::Model* model_ = nullptr;
  SourceSkeleton source_;
  BodyRetargetOptions options_;
  std::array<int, sim::kBoneCount> source_parent_{};  // nearest present ancestor; -1: none
  std::array<sim::Quat, sim::kBoneCount> source_rest_world_{};
  std::array<sim::Quat, sim::kBoneCount> align_{};
  // The humanoid, resolved once (rig.hpp's content, kept here so the header stays public).
  std::array<sim::Vec3, sim::kBoneCount> dir_{};  // unit rest direction, body frame
  std::array<double, sim::kBoneCount> length_{};
  std::array<sim::Quat, sim::kBoneCount> rest_world_{};
  sim::Vec3 hip_mid_ = sim::Vec3::Zero();         // humanoid's mid-hip, Hips frame
  sim::Vec3 source_hip_mid_ = sim::Vec3::Zero();  // source's mid-hip, its Hips frame
  double scale_ = 1.0;
  double z_offset_ = 0.0;
};

struct BodyRetargetBuild {
  std::optional<BodyRetarget> retarget;  // empty when error is set
  std::string error;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

}  // namespace tonus::reference
