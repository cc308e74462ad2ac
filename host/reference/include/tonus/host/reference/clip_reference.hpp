// A motion clip turned into the humanoid's reference configurations, so the
// avatar controller can track a real recording.
//
// Method (direction matching, "swing retargeting"): every bone of the
// humanoid (sim/humanoid.hpp) is turned so its rest direction points along the
// clip's segment between the same two joints; the root's orientation comes
// from the pelvis (hip line, lumbar spine), the trunk's twist from the shoulder
// line, elbows and knees are fitted to the limb's plane (hinge angle, the
// rest of the swing pushed into the upper bone so the wrist or ankle still
// points right), hands, feet and head take their roll from the clip's bone
// rotations (axes calibrated over the clip, so no rest-pose convention is
// assumed). Every joint is clamped into the model's limits. The root follows
// the clip's mid-hip point scaled by the ratio of leg lengths, its height set
// so the feet standing in the clip stand on z = 0.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tonus/host/balance/landmarks.hpp"
#include "tonus/host/balance/stage.hpp"
#include "tonus/sim/capacity.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference {

struct ClipReference {
  double dt_s = 0.0;            // time between frames
  std::size_t first_frame = 0;  // frames before it are a leading T-pose (kept, as the clip has them)
  int nq = 0;                   // entries of each configuration in use (the model's nq)
  std::vector<std::array<double, sim::kMaxQpos>> qpos;  // one configuration per clip frame, the model's qpos layout
  double scale = 1.0;            // humanoid leg length / clip leg length, applied to the root's path
  double ground_offset_m = 0.0;  // added to the scaled clip heights so the standing feet touch z = 0
  std::array<std::size_t, sim::kBoneCount> clamped_frames{};  // per joint (Bone order): frames clamped into its limits
  std::size_t frames_clamped = 0;                             // frames with any joint clamped
  std::vector<std::string> messages;                          // what was assumed, measured and clamped
  std::string balance;  // the balance stage's figures, also among the messages (empty: the stage was off)
  std::string error;    // non-empty: no configurations were made

  [[nodiscard]] bool ok() const { return error.empty(); }
};

// The clip's frames as configurations of `humanoid` (the model
// sim::build_humanoid makes, any height). Never throws; a bad model or motion
// comes back as `error`.
ClipReference clip_to_reference(const sim::Model& humanoid, const balance::HumanMotion& motion);

// Reads a BVH file, maps its skeleton (balance::map_skeleton), converts it
// (balance::convert_motion, unit guessed) and retargets it; any failure on
// the way is the error.
ClipReference clip_to_reference(const sim::Model& humanoid, const std::string& bvh_path);

// The same, with the balance filter run on the clip's motion before it is
// retargeted (balance::balance_stage; off: as above). Its figures go to
// `messages`; a refusal by the filter is the error.
ClipReference clip_to_reference(const sim::Model& humanoid, const std::string& bvh_path,
                                const balance::BalanceStageOptions& balance);

}  // namespace tonus::reference
