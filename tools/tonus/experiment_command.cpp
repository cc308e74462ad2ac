// `tonus experiment`: runs one experiment, prints it, writes its reports.
#include "experiment_command.hpp"

#include <fmt/core.h>

#include <fstream>

#include "experiments/reports.hpp"
#include "experiments/scene.hpp"

namespace tonus::tools {

namespace ex = tonus::experiments;

namespace {

bool write_json(const std::string& path, const nlohmann::json& j) {
  if (path.empty()) return true;
  std::ofstream f(path);
  f << j.dump(2) << '\n';
  f.close();
  if (!f) fmt::print(stderr, "tonus experiment: cannot write {}\n", path);
  return static_cast<bool>(f);
}

int finish(const std::vector<ex::Goal>& goals, bool quiet) {
  bool all = true;
  for (const ex::Goal& g : goals) {
    all = all && g.met;
    if (!quiet) fmt::print("  goal: {:<60} {}\n", g.what, g.met ? "met" : "NOT MET");
  }
  return all ? 0 : 1;
}

void print_mode(const ex::CubeMode& m) {
  fmt::print("  {:<8} gains: elbow kp {:.1f} N m/rad, kd {:.2f} N m s/rad ({:.2f} Hz)\n", m.mode, m.elbow_kp,
             m.elbow_kd, m.arm_frequency_hz);
  fmt::print(
      "           hand error before the drop {:.2f} mm; impact after {:.3f} s; peak deflection {:.1f} mm; "
      "settled in {:.2f} s at {:.1f} mm; cube {}\n",
      1e3 * m.hand_error_before_drop_m, m.impact_time_s, 1e3 * m.peak_deflection_m, m.settling_time_s,
      1e3 * m.final_deflection_m, m.cube_stayed ? "stayed on the hand" : "fell off");
}

int cube(const sim::Model& m, const ExperimentOptions& opt) {
  ex::CubeOnHandOptions o;
  o.stiffness = opt.stiffness;
  const ex::CubeOnHandResult r = ex::run_cube_on_hand(m, o);
  if (!r.error.empty()) {
    fmt::print(stderr, "tonus experiment cube-on-hand: {}\n", r.error);
    return 2;
  }
  if (!opt.quiet) {
    fmt::print(
        "cube-on-hand: kinematic root, right forearm forward with the hand level, a 1 kg cube dropped from "
        "0.3 m; stiffness {:.2f}\n",
        opt.stiffness);
    print_mode(r.pd_only);
    print_mode(r.pd_ff);
    fmt::print("  gain sweep (arm natural frequency: cube kept PD only / PD + FF, peak deflection):\n");
    for (const ex::CubeSweepPoint& p : r.sweep) {
      fmt::print("    {:5.1f} Hz: {:<4} / {:<4}  {:6.1f} / {:6.1f} mm\n", p.arm_frequency_hz,
                 p.stayed_pd_only ? "kept" : "fell", p.stayed_pd_ff ? "kept" : "fell", 1e3 * p.peak_pd_only_m,
                 1e3 * p.peak_pd_ff_m);
    }
  }
  std::string err;
  if (!write_json(opt.json, ex::to_json(r))) return 2;
  if (!opt.svg.empty() && !ex::write_cube_svg(opt.svg, r, err)) {
    fmt::print(stderr, "tonus experiment: {}\n", err);
    return 2;
  }
  return finish(ex::cube_goals(r), opt.quiet);
}

int brace(const sim::Model& m, const ExperimentOptions& opt) {
  const ex::BraceResult r = ex::run_brace(m, ex::BraceOptions{});
  if (!r.error.empty()) {
    fmt::print(stderr, "tonus experiment brace: {}\n", r.error);
    return 2;
  }
  if (!opt.quiet) {
    fmt::print("brace: a 0.45 kg ball thrown at 8 m/s, kinematic root, arms down\n");
    for (const ex::BraceTarget& t : r.targets) {
      fmt::print("  at the {}:\n", t.name);
      for (const ex::BracePoint& p : t.points) {
        fmt::print(
            "    stiffness {:.2f} (trunk {:.2f} Hz): peak deflection {:6.1f} mm, {:.3f} s after contact, "
            "impulse {:.2f} N s\n",
            p.stiffness, p.trunk_frequency_hz, 1e3 * p.peak_deflection_m, p.time_to_peak_s, p.impulse_ns);
      }
    }
  }
  std::string err;
  if (!write_json(opt.json, ex::to_json(r))) return 2;
  if (!opt.svg.empty() && !ex::write_brace_svg(opt.svg, r, err)) {
    fmt::print(stderr, "tonus experiment: {}\n", err);
    return 2;
  }
  return finish(ex::brace_goals(r), opt.quiet);
}

int track(const sim::Model& m, const ExperimentOptions& opt) {
  ex::TrackOptions o;
  o.clips = opt.clips;
  if (o.clips.empty()) o.clips.push_back(std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh");
  o.max_seconds = opt.seconds;
  const ex::TrackResult r = ex::run_track(m, o);
  if (!r.error.empty()) {
    fmt::print(stderr, "tonus experiment track: {}\n", r.error);
    return 2;
  }
  if (!opt.quiet) {
    fmt::print("track: each clip as the reference (kinematic root, stiffness 0.5, no objects)\n");
    for (const ex::ClipTrack& c : r.clips) {
      fmt::print("  {} ({:.1f} s, {} frames, {} clamped by the retargeting):\n", c.clip, c.duration_s, c.frames,
                 c.frames_clamped);
      for (const ex::VariantTrack& v : c.variants) {
        fmt::print(
            "    {:<16} RMS {:5.2f} deg (max {:5.1f}), hands {:5.1f} mm RMS, lag {:3.0f} ms; tick mean {:5.1f} us, "
            "p99 {:6.1f}, max {:7.1f}\n",
            avatar::to_string(v.variant), v.rms_all_rad * 180.0 / M_PI, v.max_rad * 180.0 / M_PI, 1e3 * v.hand_rms_m,
            1e3 * v.lag_s, v.tick_mean_us, v.tick_p99_us, v.tick_max_us);
      }
    }
    fmt::print("  the same impact (0.45 kg ball at 8 m/s at the chest, arms down):\n");
    for (const ex::ImpactReaction& i : r.impact)
      fmt::print("    {:<16} chest peak deflection {:5.2f} mm, impulse {:.2f} N s\n", avatar::to_string(i.variant),
                 1e3 * i.peak_deflection_m, i.impulse_ns);
  }
  std::string err;
  if (!write_json(opt.json, ex::to_json(r))) return 2;
  if (!opt.svg.empty() && !ex::write_track_svg(opt.svg, r, err)) {
    fmt::print(stderr, "tonus experiment: {}\n", err);
    return 2;
  }
  return finish(ex::track_goals(r), opt.quiet);
}

}  // namespace

int run_experiment(const ExperimentOptions& opt) {
  std::string err;
  const auto model = ex::humanoid_model(err);
  if (!model) {
    fmt::print(stderr, "tonus experiment: {}\n", err);
    return 2;
  }
  if (opt.name == "cube-on-hand") return cube(*model, opt);
  if (opt.name == "brace") return brace(*model, opt);
  if (opt.name == "track") return track(*model, opt);
  fmt::print(stderr, "tonus experiment: unknown experiment '{}' (cube-on-hand, brace, track)\n", opt.name);
  return 2;
}

}  // namespace tonus::tools
