// JSON and SVG reports of the experiments, and their goals.
#include "reports.hpp"

#include <cmath>

#include "svg_plot.hpp"

namespace tonus::experiments {

using nlohmann::json;

namespace {

json mode_json(const CubeMode& m) {
  return {{"hand_error_before_drop_m", m.hand_error_before_drop_m},
          {"peak_deflection_m", m.peak_deflection_m},
          {"settling_time_s", m.settling_time_s},
          {"final_deflection_m", m.final_deflection_m},
          {"impact_time_s", m.impact_time_s},
          {"cube_stayed", m.cube_stayed},
          {"gains",
           {{"stiffness", m.stiffness},
            {"arm_frequency_hz", m.arm_frequency_hz},
            {"elbow_kp_nm_per_rad", m.elbow_kp},
            {"elbow_kd_nms_per_rad", m.elbow_kd}}}};
}

}  // namespace

json goals_json(const std::vector<Goal>& goals) {
  json g = json::array();
  for (const Goal& x : goals) g.push_back({{"goal", x.what}, {"met", x.met}});
  return g;
}

std::vector<Goal> cube_goals(const CubeOnHandResult& r) {
  const double a = r.pd_only.peak_deflection_m, b = r.pd_ff.peak_deflection_m;
  return {{"PD + FF hand error before the drop < 1 mm", r.pd_ff.hand_error_before_drop_m < 1e-3},
          {"PD only sags before the drop (hand error > 5 mm)", r.pd_only.hand_error_before_drop_m > 5e-3},
          {"peak deflections within 10 % between the modes", std::abs(a - b) <= 0.1 * std::max(a, b)},
          {"the cube stays on the hand in both modes", r.pd_only.cube_stayed && r.pd_ff.cube_stayed}};
}

json to_json(const CubeOnHandResult& r) {
  json sweep = json::array();
  for (const CubeSweepPoint& p : r.sweep) {
    sweep.push_back({{"arm_frequency_hz", p.arm_frequency_hz},
                     {"pd_only",
                      {{"cube_stayed", p.stayed_pd_only},
                       {"peak_deflection_m", p.peak_pd_only_m},
                       {"hand_error_before_drop_m", p.error_pd_only_m}}},
                     {"pd_ff",
                      {{"cube_stayed", p.stayed_pd_ff},
                       {"peak_deflection_m", p.peak_pd_ff_m},
                       {"hand_error_before_drop_m", p.error_pd_ff_m}}}});
  }
  return {{"experiment", "cube-on-hand"},
          {"pd_only", mode_json(r.pd_only)},
          {"pd_ff", mode_json(r.pd_ff)},
          {"gain_sweep", sweep},
          {"goals", goals_json(cube_goals(r))}};
}

bool write_cube_svg(const std::string& path, const CubeOnHandResult& r, std::string& error) {
  Panel drop{"Hand height after the drop, from just before it", "time after the drop, s", "height change, mm", {}};
  for (const CubeMode* m : {&r.pd_only, &r.pd_ff}) {
    Series s{m->mode == "pd_only" ? "PD only" : "PD + FF", m->t_s, m->hand_dz_m, false};
    for (double& y : s.y) y *= 1e3;
    drop.series.push_back(std::move(s));
  }
  Panel peak{"Gain sweep: peak deflection where the cube stayed on the hand",
             "arm natural frequency, Hz",
             "peak deflection, mm",
             {}};
  Panel sag{"Gain sweep: hand error before the drop", "arm natural frequency, Hz", "hand error, mm", {}};
  Series so{"PD only", {}, {}, true}, sf{"PD + FF", {}, {}, true};
  Series eo{"PD only", {}, {}, false}, ef{"PD + FF", {}, {}, false};
  for (const CubeSweepPoint& p : r.sweep) {
    if (p.stayed_pd_only) so.x.push_back(p.arm_frequency_hz), so.y.push_back(1e3 * p.peak_pd_only_m);
    if (p.stayed_pd_ff) sf.x.push_back(p.arm_frequency_hz), sf.y.push_back(1e3 * p.peak_pd_ff_m);
    eo.x.push_back(p.arm_frequency_hz);
    eo.y.push_back(1e3 * p.error_pd_only_m);
    ef.x.push_back(p.arm_frequency_hz);
    ef.y.push_back(1e3 * p.error_pd_ff_m);
  }
  peak.series = {so, sf};
  sag.series = {eo, ef};
  return write_svg(path, "cube-on-hand: 1 kg cube dropped from 0.3 m onto the right hand", {drop, peak, sag}, error);
}

std::vector<Goal> brace_goals(const BraceResult& r) {
  std::vector<Goal> g;
  for (const BraceTarget& t : r.targets) {
    g.push_back({"the " + t.name + "'s peak deflection falls strictly with stiffness", t.strictly_decreasing});
    bool back = !t.points.empty();
    for (const BracePoint& p : t.points) back = back && p.final_deflection_m < 0.005;
    g.push_back({"the " + t.name + " comes back within 5 mm at every stiffness", back});
  }
  return g;
}

json to_json(const BraceResult& r) {
  json j = {{"experiment", "brace"}};
  for (const BraceTarget& t : r.targets) {
    json pts = json::array();
    for (const BracePoint& p : t.points) {
      pts.push_back({{"stiffness", p.stiffness},
                     {"peak_deflection_m", p.peak_deflection_m},
                     {"time_to_peak_s", p.time_to_peak_s},
                     {"impulse_ns", p.impulse_ns},
                     {"final_deflection_m", p.final_deflection_m},
                     {"trunk_frequency_hz", p.trunk_frequency_hz},
                     {"hit", p.hit}});
    }
    j[t.name] = pts;
  }
  j["goals"] = goals_json(brace_goals(r));
  return j;
}

bool write_brace_svg(const std::string& path, const BraceResult& r, std::string& error) {
  std::vector<Panel> panels;
  for (const BraceTarget& t : r.targets) {
    Panel p{"Ball at the " + t.name + ": the " + t.name + "'s displacement",
            "time after the throw, s",
            "displacement, mm",
            {}};
    for (const BracePoint& x : t.points) {
      Series s{"stiffness " + std::to_string(x.stiffness).substr(0, 4), x.t_s, x.deflection_m, false};
      for (double& y : s.y) y *= 1e3;
      p.series.push_back(std::move(s));
    }
    panels.push_back(std::move(p));
  }
  return write_svg(path, "brace: a 0.45 kg ball at 8 m/s, five stiffness levels", panels, error);
}

namespace {

const VariantTrack* find(const ClipTrack& c, avatar::Feedforward v) {
  for (const VariantTrack& x : c.variants) {
    if (x.variant == v) return &x;
  }
  return nullptr;
}

}  // namespace

std::vector<Goal> track_goals(const TrackResult& r) {
  std::vector<Goal> g;
  for (const ClipTrack& c : r.clips) {
    const VariantTrack* a = find(c, avatar::Feedforward::simulation);
    const VariantTrack* b = find(c, avatar::Feedforward::inverse_dynamics);
    const VariantTrack* n = find(c, avatar::Feedforward::none);
    if (a == nullptr || b == nullptr || n == nullptr) continue;
    g.push_back({c.clip + ": both feedforward variants track closer than PD only",
                 a->rms_all_rad < n->rms_all_rad && b->rms_all_rad < n->rms_all_rad});
    g.push_back({c.clip + ": no resets of A or B", a->resets + b->resets + n->resets == 0});
  }
  return g;
}

json to_json(const TrackResult& r) {
  json clips = json::array();
  for (const ClipTrack& c : r.clips) {
    json variants = json::object();
    for (const VariantTrack& v : c.variants) {
      json per_joint = json::object();
      for (std::size_t b = 1; b < sim::kBoneCount; ++b) per_joint[std::string(sim::kBones[b].name)] = v.rms_rad[b];
      variants[std::string(avatar::to_string(v.variant))] = {
          {"rms_rad", per_joint},
          {"rms_all_joints_rad", v.rms_all_rad},
          {"max_rad", v.max_rad},
          {"hand_rms_m", v.hand_rms_m},
          {"reference_lag_s", v.lag_s},
          {"tick_us",
           {{"mean", v.tick_mean_us}, {"p50", v.tick_p50_us}, {"p99", v.tick_p99_us}, {"max", v.tick_max_us}}},
          {"reference_jumps", v.jumps},
          {"reference_clamped_ticks", v.clamped},
          {"resets", v.resets}};
    }
    clips.push_back({{"clip", c.clip},
                     {"seconds", c.duration_s},
                     {"frames", c.frames},
                     {"frames_clamped_by_retargeting", c.frames_clamped},
                     {"variants", variants}});
  }
  json impact = json::object();
  for (const ImpactReaction& i : r.impact)
    impact[std::string(avatar::to_string(i.variant))] = {{"chest_peak_deflection_m", i.peak_deflection_m},
                                                         {"impulse_ns", i.impulse_ns}};
  return {{"experiment", "track"},
          {"clips", clips},
          {"impact_ball_at_chest", impact},
          {"goals", goals_json(track_goals(r))}};
}

bool write_track_svg(const std::string& path, const TrackResult& r, std::string& error) {
  std::vector<Panel> panels;
  for (const ClipTrack& c : r.clips) {
    Panel p{c.clip + ": RMS tracking error per joint (1 Spine ... 20 RightToes)",
            "joint (Bone index)",
            "RMS error, degrees",
            {}};
    for (const VariantTrack& v : c.variants) {
      Series s{std::string(avatar::to_string(v.variant)), {}, {}, true};
      for (std::size_t b = 1; b < sim::kBoneCount; ++b) {
        s.x.push_back(static_cast<double>(b));
        s.y.push_back(v.rms_rad[b] * 180.0 / M_PI);
      }
      p.series.push_back(std::move(s));
    }
    panels.push_back(std::move(p));
  }
  return write_svg(path, "track: a captured clip as the reference, three feedforward variants", panels, error);
}

}  // namespace tonus::experiments
