// `tonus experiment NAME`: the avatar controller's experiments (cube-on-hand,
// brace, track), each printing a summary and writing a JSON report and an
// SVG plot. Exit code 0 when the experiment's goals are met, 1 when one is
// not, 2 for bad input.
#pragma once

#include <string>
#include <vector>

namespace tonus::tools {

struct ExperimentOptions {
  std::string name;
  std::string json;                // write the JSON report here (empty: none)
  std::string svg;                 // write the plot here (empty: none)
  double stiffness = 1.0;          // cube-on-hand: the performer's stiffness (every group)
  std::vector<std::string> clips;  // track: BVH clips (default: the bundled CMU walk)
  double seconds = 10.0;           // track: at most this much of each clip
  bool quiet = false;
};

int run_experiment(const ExperimentOptions& opt);

}  // namespace tonus::tools
