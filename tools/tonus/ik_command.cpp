#include "ik_command.hpp"

#include <fmt/core.h>

#include <fstream>
#include <sstream>

#include "experiments/ik_eval.hpp"
#include "experiments/ik_report.hpp"

namespace tonus::tools {

namespace ex = tonus::experiments;

int run_ik_command(const IkCommandOptions& opt) {
  ex::IkEvalOptions o;
  o.clip = opt.clip;
  o.trackers = opt.trackers;
  o.max_seconds = opt.seconds;
  if (!opt.mapping.empty()) {
    std::ifstream in(opt.mapping);
    if (!in) {
      fmt::print(stderr, "tonus ik: cannot read the mapping file {}\n", opt.mapping);
      return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    o.mapping_text = text.str();
  }
  const ex::IkEvalResult r = ex::run_ik_eval(o);
  if (!r.error.empty()) {
    fmt::print(stderr, "tonus ik: {}\n", r.error);
    return 2;
  }
  if (!opt.quiet) {
    fmt::print("tonus ik: {} ({} trackers)\n", r.clip, r.trackers);
    std::string bones;
    for (const auto& [bone, joint] : r.mapping) {
      if (joint.empty()) continue;
      if (!bones.empty()) bones += ", ";
      bones += bone;
      bones += '=';
      bones += joint;
    }
    fmt::print("  skeleton: {}; bones: {}\n", r.convention, bones);
    fmt::print("  stature: clip {:.3f} m, calibrated from a T-pose {:.3f} m (arm scale {:.3f})\n", r.truth_height_m,
               r.calibrated_height_m, r.arm_scale);
    for (const ex::IkRun& run : r.runs) {
      fmt::print(
          "  {:<9} {} frames: MPJPE {:5.2f} cm (upper {:5.2f}, lower {:5.2f}; p95 {:5.2f}, max {:5.2f}); "
          "wrist to tracker: within 1 mm {:.1f} %, p95 {:.2f} mm, max {:.1f}; head max {:.3f} mm; jitter x{:.2f} of "
          "the clip's; "
          "{} steps; solve {:.1f} us mean, p99 {:.1f}\n",
          run.condition, run.frames, run.mpjpe_cm, run.mpjpe_upper_cm, run.mpjpe_lower_cm, run.mpjpe_p95_cm,
          run.mpjpe_max_cm, 100.0 * run.hand_within_1mm_share, run.hand_error_p95_mm, run.hand_error_max_mm,
          run.head_error_max_mm, run.jitter_ratio, run.steps, run.solve_mean_us, run.solve_p99_us);
      if (run.condition == "clean") {
        std::string per;
        for (std::size_t b = 0; b < run.joint_error_cm.size(); ++b) {
          per += fmt::format("{}{} {:.1f} cm (jitter x{:.2f})", b ? ", " : "", r.mapping[b].first,
                             run.joint_error_cm[b], run.joint_jitter_ratio[b]);
        }
        fmt::print("            per joint: {}\n", per);
      }
    }
  }
  if (!opt.json.empty()) {
    std::ofstream f(opt.json);
    f << ex::to_json(r).dump(2) << '\n';
    f.close();
    if (!f) {
      fmt::print(stderr, "tonus ik: cannot write {}\n", opt.json);
      return 2;
    }
  }
  std::string err;
  if (!opt.svg.empty() && !ex::write_ik_svg(opt.svg, r, err)) {
    fmt::print(stderr, "tonus ik: {}\n", err);
    return 2;
  }
  return 0;
}

}  // namespace tonus::tools
