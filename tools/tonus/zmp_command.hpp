// `tonus zmp IN.bvh -o OUT.bvh`: the ZMP balance filter as a tool. Reads a
// clip, analyses its zero moment point against the feet's support polygon,
// corrects the waist rotation where the ZMP leaves it, writes the corrected
// clip, and reports before and after (text; optionally CSV per frame, a JSON
// report and an SVG plot).
#pragma once

#include <optional>
#include <string>

#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/balance/robust_filter.hpp"

namespace tonus::tools {

struct ZmpCommandOptions {
  std::string input;
  std::string output;   // corrected BVH (empty: analysis only)
  std::string csv;      // per-frame ZMP before/after
  std::string json;     // machine-readable report
  std::string svg;      // plot of the ZMP trajectories
  std::string mapping;  // a mapping file overriding the skeleton's joint names
  std::string unit;     // m, cm, mm, inch, cmu, or metres per unit; empty: guess
  double body_mass_kg = 70.0;
  std::string sex = "male";
  std::string trunk = "spine";
  bool both_trunks = false;
  std::optional<double> foot_length_m;
  std::optional<double> ground_height_m;
  double contact_height_m = 0.025;
  double contact_speed_mps = 0.30;
  std::string derivative = "kalman_spline";  // kalman_spline, kalman, spline, finite_difference
  double cutoff_hz = 6.0;
  bool full_zmp = false;  // include the segments' angular momentum rate
  std::string correction =
      "waist";                // waist (the robust filter, the default) or rotation (waist rotation, one estimator)
  bool online = false;        // the streaming filter (pelvis shift by preview control, bounded look-ahead)
  double lookahead_s = 0.25;  // --online: how far ahead it sees, s (at most 0.25)
  // --online: the planner's violation weight (0: the plain preview).
  double plan_weight = balance::OnlineOptions{}.constraint_weight;
  // --online: the window's smoothers' cut-off, Hz (--cutoff is the analysis's).
  double window_cutoff_hz = balance::OnlineOptions{}.window_cutoff_hz;
  double margin_m = -1.0;  // negative: the correction's own (rotation 1 cm, waist 2 cm, online 1.5 cm)
  double max_correction_rad = 1.0;
  // The robust filter's largest swing of each arm, rad (0: the arms are left as captured).
  double max_arm_swing_rad = balance::RobustFilterOptions{}.max_arm_swing_rad;
  double arm_weight = balance::RobustFilterOptions{}.arm_weight;  // its cost per radian
  int max_iterations = 100;
  bool keep_tpose = false;
  bool quiet = false;
};

// Process exit code: 0 when the written clip is balanced under every
// estimator of the family (--correction rotation: when every analysed frame
// ends inside its support polygon, or airborne, under its one estimator), 1
// when it is not, 2 on bad input.
int run_zmp_command(const ZmpCommandOptions& options);

}  // namespace tonus::tools
