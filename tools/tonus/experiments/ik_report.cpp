#include "ik_report.hpp"

#include "svg_plot.hpp"

namespace tonus::experiments {
namespace {

nlohmann::json run_json(const IkRun& r) {
  return {{"condition", r.condition},
          {"frames", r.frames},
          {"mpjpe_cm", r.mpjpe_cm},
          {"mpjpe_upper_cm", r.mpjpe_upper_cm},
          {"mpjpe_lower_cm", r.mpjpe_lower_cm},
          {"mpjpe_p95_cm", r.mpjpe_p95_cm},
          {"mpjpe_max_cm", r.mpjpe_max_cm},
          {"hand_error_mean_mm", r.hand_error_mean_mm},
          {"hand_error_max_mm", r.hand_error_max_mm},
          {"hand_error_p95_mm", r.hand_error_p95_mm},
          {"hand_within_1mm_share", r.hand_within_1mm_share},
          {"hand_error_max_reached_mm", r.hand_error_max_reached_mm},
          {"head_error_mean_mm", r.head_error_mean_mm},
          {"head_error_max_mm", r.head_error_max_mm},
          {"hand_to_clip_mean_mm", r.hand_truth_mean_mm},
          {"jitter_mps3", r.jitter_mps3},
          {"jitter_ratio", r.jitter_ratio},
          {"velocity_error_mps", r.velocity_error_mps},
          {"steps", r.steps},
          {"clamped_frames", r.clamped_frames},
          {"flagged_frames", r.flagged_frames},
          {"hand_unreachable_frames", r.unreachable_frames},
          {"foot_unreachable_frames", r.foot_unreachable_frames},
          {"solve_mean_us", r.solve_mean_us},
          {"solve_p99_us", r.solve_p99_us},
          {"solve_max_us", r.solve_max_us}};
}

}  // namespace

nlohmann::json to_json(const IkEvalResult& r) {
  nlohmann::json j;
  j["clip"] = r.clip;
  j["trackers"] = r.trackers;
  j["convention"] = r.convention;
  nlohmann::json map = nlohmann::json::object();
  for (const auto& [bone, joint] : r.mapping)
    map[bone] = joint.empty() ? nlohmann::json(nullptr) : nlohmann::json(joint);
  j["mapping"] = map;
  j["frame_time_s"] = r.frame_time_s;
  j["clip_stature_m"] = r.truth_height_m;
  j["calibrated_stature_m"] = r.calibrated_height_m;
  j["calibrated_arm_scale"] = r.arm_scale;
  j["source_jitter_mps3"] = r.source_jitter_mps3;
  // The clean run's figures at the top level, as outside checks read them.
  if (!r.runs.empty()) {
    const nlohmann::json clean = run_json(r.runs.front());
    for (const char* k : {"frames", "mpjpe_cm", "mpjpe_upper_cm", "mpjpe_lower_cm", "hand_error_max_mm",
                          "head_error_max_mm", "jitter_ratio"}) {
      j[k] = clean[k];
    }
    // Per joint of the clean run: where the error and the extra jerk are.
    nlohmann::json joints = nlohmann::json::object();
    const IkRun& c = r.runs.front();
    for (std::size_t b = 0; b < r.mapping.size() && b < c.joint_error_cm.size(); ++b) {
      joints[r.mapping[b].first] = {{"error_cm", c.joint_error_cm[b]},
                                    {"jitter_ratio", c.joint_jitter_ratio[b]},
                                    {"jitter_excess", c.joint_jitter_excess[b]}};
    }
    j["joints"] = joints;
  }
  nlohmann::json runs = nlohmann::json::array();
  for (const IkRun& run : r.runs) runs.push_back(run_json(run));
  j["runs"] = runs;
  j["messages"] = r.messages;
  return j;
}

bool write_ik_svg(const std::string& path, const IkEvalResult& r, std::string& error) {
  std::vector<Panel> panels;
  Panel mp{"Mean joint position error per frame", "time (s)", "MPJPE (cm)", {}};
  Panel hand{"Worst wrist error against its tracker", "time (s)", "mm", {}};
  Panel ankle{"Left ankle along x: clip against solution (clean)", "time (s)", "m", {}};
  for (const IkRun& run : r.runs) {
    Series s{run.condition, {}, {}, false};
    Series h{run.condition, {}, {}, false};
    for (std::size_t f = 0; f < run.frame_mpjpe_cm.size(); ++f) {
      const double t = static_cast<double>(f) * r.frame_time_s;
      s.x.push_back(t);
      s.y.push_back(run.frame_mpjpe_cm[f]);
      h.x.push_back(t);
      h.y.push_back(run.frame_hand_mm[f]);
    }
    mp.series.push_back(std::move(s));
    hand.series.push_back(std::move(h));
  }
  if (!r.runs.empty()) {
    const IkRun& clean = r.runs.front();
    Series truth{"clip", {}, {}, false}, solved{"solution", {}, {}, false};
    for (std::size_t f = 0; f < clean.ankle_x_truth_m.size(); ++f) {
      const double t = static_cast<double>(f) * r.frame_time_s;
      truth.x.push_back(t);
      truth.y.push_back(clean.ankle_x_truth_m[f]);
      solved.x.push_back(t);
      solved.y.push_back(clean.ankle_x_solved_m[f]);
    }
    ankle.series = {truth, solved};
  }
  panels = {mp, hand, ankle};
  return write_svg(path, "tonus ik: " + r.clip + " (" + std::to_string(r.trackers) + " trackers)", panels, error);
}

}  // namespace tonus::experiments
