// Following real motion: a captured clip as the reference, no objects, for
// each feedforward variant ((a) simulation A's torque, (b) inverse dynamics
// with fixed-lag derivatives, (c) none): B's per-joint RMS tracking error,
// the cost per tick, and the reaction to the same impact (a ball at the chest).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "tonus/host/avatar/controller.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::experiments {

struct TrackOptions {
  std::vector<std::string> clips;  // BVH paths
  double max_seconds = 10.0;       // of each clip
  double stiffness = 0.5;          // every group
};

struct VariantTrack {
  avatar::Feedforward variant = avatar::Feedforward::simulation;
  std::array<double, sim::kBoneCount> rms_rad{};  // per joint (root: 0)
  double rms_all_rad = 0.0;                       // over every joint and tick
  double max_rad = 0.0;
  double hand_rms_m = 0.0;  // both hands' position error, RMS
  double lag_s = 0.0;       // how late the reference is followed ((b) only)
  double tick_mean_us = 0.0, tick_p50_us = 0.0, tick_p99_us = 0.0, tick_max_us = 0.0;
  std::uint64_t jumps = 0, clamped = 0, resets = 0;
};

struct ClipTrack {
  std::string clip;
  double duration_s = 0.0;
  std::size_t frames = 0;
  std::size_t frames_clamped = 0;
  std::vector<std::string> messages;
  std::vector<VariantTrack> variants;
};

struct ImpactReaction {
  avatar::Feedforward variant = avatar::Feedforward::simulation;
  double peak_deflection_m = 0.0;  // the chest's
  double impulse_ns = 0.0;
};

struct TrackResult {
  std::vector<ClipTrack> clips;
  std::vector<ImpactReaction> impact;
  std::string error;
};

TrackResult run_track(const sim::Model& m, const TrackOptions& opt);

}  // namespace tonus::experiments
