// The paper's cube experiment (Fig. 3 and 4): kinematic root, the right
// forearm held forward with the hand level, a 1 kg cube dropped from 0.3 m
// onto the hand. PD only against PD + feedforward at the same weak gains:
// before the drop PD only sags under gravity while PD + FF holds the
// reference; after it both react alike. A sweep over the arm's natural
// frequency shows where the cube stays on the hand.
#pragma once

#include <string>
#include <vector>

#include "tonus/sim/model.hpp"

namespace tonus::experiments {

struct CubeOnHandOptions {
  double stiffness = 1.0;  // the performer's stiffness for every group (braced, as for a catch)
  double settle_s = 2.0;   // held before the drop
  double after_s = 3.0;    // watched after the drop
  double drop_height_m = 0.3;
  double cube_mass_kg = 1.0;
  double cube_edge_m = 0.08;
  std::vector<double> sweep_hz{0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0};  // arm natural frequencies
};

struct CubeMode {
  std::string mode;  // "pd_only" or "pd_ff"
  double stiffness = 0.0;
  double arm_frequency_hz = 0.0;
  double elbow_kp = 0.0;                  // N m/rad
  double elbow_kd = 0.0;                  // N m s/rad
  double hand_error_before_drop_m = 0.0;  // |hand - reference hand| just before the drop
  double peak_deflection_m = 0.0;         // largest hand displacement from its pre-drop place
  double settling_time_s = 0.0;           // from the impact until the hand stays within 5 % of the peak (>= 2 mm)
  double final_deflection_m = 0.0;        // where it settled, from its pre-drop place
  double impact_time_s = 0.0;             // after the drop
  bool cube_stayed = false;
  std::vector<double> t_s, hand_dz_m;  // hand height change over time (for the plot)
};

struct CubeSweepPoint {
  double arm_frequency_hz = 0.0;
  bool stayed_pd_only = false, stayed_pd_ff = false;
  double peak_pd_only_m = 0.0, peak_pd_ff_m = 0.0;
  double error_pd_only_m = 0.0, error_pd_ff_m = 0.0;
};

struct CubeOnHandResult {
  CubeMode pd_only, pd_ff;
  std::vector<CubeSweepPoint> sweep;
  std::string error;
};

CubeOnHandResult run_cube_on_hand(const sim::Model& m, const CubeOnHandOptions& opt);

}  // namespace tonus::experiments
