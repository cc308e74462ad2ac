// Bracing against a hit: a 0.45 kg ball thrown at 8 m/s at the chest and at
// the head, at stiffness 0, 0.25, 0.5, 0.75 and 1 (every group). A stiffer
// performer's avatar is pushed less: the hit segment's peak deflection must
// fall strictly as the stiffness rises.
#pragma once

#include <string>
#include <vector>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::experiments {

struct BraceOptions {
  std::vector<double> stiffness{0.0, 0.25, 0.5, 0.75, 1.0};
  double ball_mass_kg = 0.45;
  double ball_radius_m = 0.11;
  double ball_speed_mps = 8.0;
  double settle_s = 0.5;
  double after_s = 1.5;
};

struct BracePoint {
  double stiffness = 0.0;
  double trunk_frequency_hz = 0.0;
  double peak_deflection_m = 0.0;   // largest displacement of the hit segment's centre from its place before the throw
  double time_to_peak_s = 0.0;      // from the first contact
  double impulse_ns = 0.0;          // total normal impulse the ball gave the body
  double final_deflection_m = 0.0;  // where the segment is at the end: it must come back (no flop)
  bool hit = false;
  std::vector<double> t_s, deflection_m;  // for the plot
};

struct BraceTarget {
  std::string name;  // "chest" or "head"
  sim::Bone bone = sim::Bone::Chest;
  std::vector<BracePoint> points;
  bool strictly_decreasing = false;
};

struct BraceResult {
  std::vector<BraceTarget> targets;
  std::string error;
};

BraceResult run_brace(const sim::Model& m, const BraceOptions& opt);

}  // namespace tonus::experiments
