// How well the tracker IK (host/reference/tracker_ik.hpp) recovers a real
// full-body clip from the trackers a performer would wear. The clip is
// retargeted onto a humanoid of the clip's stature (the ground truth); its
// forward kinematics (sim's) give the tracker streams, with fixed, realistic
// tracker offsets; a standing T-pose of that humanoid is the calibration
// sample; the solve runs on the humanoid the calibration builds. Joint
// positions are compared with sim's forward kinematics of both.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tonus/host/reference/tracker_ik.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::experiments {

struct IkEvalOptions {
  std::string clip;           // BVH path
  std::string mapping_text;   // joint-name overrides, lines 'HumanBodyBone = JointName' (balance::map_skeleton)
  int trackers = 3;           // 3 (head, hands) or 6 (+ waist, feet)
  double max_seconds = 0.0;   // 0: the whole clip
  double noise_pos_m = 0.01;  // the noisy run: Gaussian, per axis
  double noise_rot_rad = 0.017453292519943295;  // ... and per rotation axis (1 degree)
  double dropout_share = 0.1;                   // the dropout run: each tracker lost about this share of the time
  double dropout_length_s = 0.5;                // in gaps of this length
  std::uint32_t seed = 1;
};

// One run of the solver over the clip.
struct IkRun {
  std::string condition;  // clean, noise, dropouts, noise_filtered (the noise through the 1-euro input filter)
  std::size_t frames = 0;
  double mpjpe_cm = 0.0, mpjpe_upper_cm = 0.0, mpjpe_lower_cm = 0.0;
  double mpjpe_p95_cm = 0.0, mpjpe_max_cm = 0.0;             // of the per-frame mean
  double hand_error_mean_mm = 0.0, hand_error_max_mm = 0.0;  // wrist against its tracker's wrist (live samples)
  double hand_error_p95_mm = 0.0;
  double hand_within_1mm_share = 0.0;      // of live hand samples
  double hand_error_max_reached_mm = 0.0;  // over frames the solver did not flag a hand unreachable
  double head_error_mean_mm = 0.0, head_error_max_mm = 0.0;
  double hand_truth_mean_mm = 0.0;  // wrist against the clip's wrist (calibration error included)
  double jitter_mps3 = 0.0;         // mean joint jerk, m/s^3
  double jitter_ratio = 0.0;        // over the clip's
  double velocity_error_mps = 0.0;  // mean per-joint velocity error
  std::uint64_t steps = 0, clamped_frames = 0, flagged_frames = 0, unreachable_frames = 0, foot_unreachable_frames = 0;
  double solve_mean_us = 0.0, solve_p99_us = 0.0, solve_max_us = 0.0;
  std::array<double, 21> joint_error_cm{};                // mean per joint (Bone order)
  std::array<double, 21> joint_jitter_ratio{};            // per joint, over the clip's
  std::array<double, 21> joint_jitter_excess{};           // per joint, (solved - clip jerk) over the clip's total
  std::vector<double> frame_mpjpe_cm, frame_hand_mm;      // per frame, for the plot
  std::vector<double> ankle_x_truth_m, ankle_x_solved_m;  // left ankle along the clip's main direction
};

struct IkEvalResult {
  std::string clip;
  std::string convention;                                    // the skeleton map's
  std::vector<std::pair<std::string, std::string>> mapping;  // humanoid bone -> clip joint
  double frame_time_s = 0.0;
  double truth_height_m = 0.0, calibrated_height_m = 0.0, arm_scale = 0.0;
  int trackers = 3;
  std::vector<IkRun> runs;  // clean, noise, dropouts, noise_filtered
  double source_jitter_mps3 = 0.0;
  std::vector<std::string> messages;
  std::string error;
};

// What a run needs, made once: the ground truth (its humanoid, its joints
// and the trackers per frame), and the calibrated humanoid and solver.
using JointJerk = std::array<double, sim::kBoneCount>;  // per joint, the summed |third difference| (m)

struct IkSetup {
  std::unique_ptr<sim::Model> model;  // the truth's humanoid
  std::vector<std::array<sim::Vec3, sim::kBoneCount>> joints;
  JointJerk jerk{};  // the truth's, per joint
  std::vector<reference::TrackerFrame> trackers;
  double dt_s = 0.0;
  std::unique_ptr<sim::Model> solved;  // the humanoid the calibration builds
  std::optional<reference::IkModel> ik;
};

// Reads, maps, retargets, synthesizes the trackers and calibrates; fills the
// result's description (or its error).
IkSetup prepare_ik_eval(const IkEvalOptions& options, IkEvalResult& result);

IkEvalResult run_ik_eval(const IkEvalOptions& options);

}  // namespace tonus::experiments
