// `tonus ik CLIP --trackers 3|6`: the tracker IK's errors on a real clip
// (experiments/ik_eval.hpp), printed, and written as JSON and an SVG plot.
// Exit code 0 when the evaluation ran, 2 for bad input (a clip that cannot
// be read or mapped).
#pragma once

#include <string>

namespace tonus::tools {

struct IkCommandOptions {
  std::string clip;
  int trackers = 3;
  std::string json, svg;
  std::string mapping;   // joint-name mapping file
  double seconds = 0.0;  // 0: the whole clip
  bool quiet = false;
};

int run_ik_command(const IkCommandOptions& opt);

}  // namespace tonus::tools
