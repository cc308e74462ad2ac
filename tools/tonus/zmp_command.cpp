#include "zmp_command.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "tonus/host/balance/apply.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/family.hpp"
#include "tonus/host/balance/filter.hpp"
#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/balance/robust_filter.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/sim/human_bones.hpp"
#include "zmp_outputs.hpp"

namespace tonus::tools {
namespace {

// Metres per file unit from the --unit option; nothing for "guess".
bool parse_unit(const std::string& text, std::optional<double>& out, std::string& error) {
  if (text.empty()) return true;
  const struct {
    const char* name;
    double metres;
  } units[] = {{"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"inch", 0.0254}, {"in", 0.0254}, {"cmu", 0.056444}};
  for (const auto& u : units) {
    if (text == u.name) {
      out = u.metres;
      return true;
    }
  }
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(v > 0.0) || !std::isfinite(v)) {
    error = "--unit: expected m, cm, mm, inch, cmu or a positive number of metres per unit, got '" + text + "'";
    return false;
  }
  out = v;
  return true;
}

bool parse_method(const std::string& text, derivatives::Method& out) {
  if (text == "kalman_spline")
    out = derivatives::Method::kalman_spline;
  else if (text == "kalman")
    out = derivatives::Method::kalman;
  else if (text == "spline")
    out = derivatives::Method::spline;
  else if (text == "finite_difference")
    out = derivatives::Method::finite_difference;
  else
    return false;
  return true;
}

struct Progress {
  bool show = false;
};

void on_progress(int iteration, std::size_t outside, void* user) {
  if (!static_cast<Progress*>(user)->show) return;
  fmt::print(stderr, "\r  balancing: iteration {:3d}, {:5d} frames still outside", iteration, outside);
  std::fflush(stderr);
}

// A member with the trunk straight says so; the default (along the spine) is unmarked.
const char* trunk_label(const balance::MemberVerdict& m) {
  return m.trunk == balance::TrunkModel::straight ? " (straight trunk)" : "";
}

// One line per member: frames outside by more than the threshold, before -> after.
void print_family(const balance::FamilyVerdict& before, const balance::FamilyVerdict& after) {
  if (after.members.empty()) return;
  fmt::print("  under each estimator (frames outside by more than {:.0f} cm, before -> after, of {} supported):\n",
             100.0 * after.threshold_m, after.members[after.worst].supported);
  std::string line;
  for (std::size_t i = 0; i < after.members.size() && i < before.members.size(); ++i) {
    const balance::MemberVerdict& a = after.members[i];
    line += fmt::format("{}{:g} Hz {}{} {} -> {}", i % 2 == 0 ? "    " : ", ", a.cutoff_hz,
                        a.full ? "full" : "particle", trunk_label(a), before.members[i].outside, a.outside);
    if (i % 2 == 1) {
      fmt::print("{}\n", line);
      line.clear();
    }
  }
  if (!line.empty()) fmt::print("{}\n", line);
  const balance::MemberVerdict& w = after.members[after.worst];
  fmt::print("  worst estimator after: {:g} Hz {}{}, {} frames ({:.1f} %): {} (at most {:.0f} %)\n", w.cutoff_hz,
             w.full ? "full" : "particle", trunk_label(w), w.outside, 100.0 * w.share(),
             after.balanced() ? "balanced" : "NOT balanced under every estimator",
             100.0 * balance::kFamilyAllowedShare);
}

// The robust filter's result in the report's shape: its figures under the
// base estimator (the family's verdict is reported beside).
balance::FilterResult as_filter_result(balance::RobustFilterResult&& r, const balance::HumanMotion& original,
                                       const balance::AnalysisOptions& base) {
  balance::FilterResult f;
  const balance::ContactTrack& contacts = r.before.front().contacts;
  f.before = balance::analyse(original, base, &contacts);
  f.after = balance::analyse(r.corrected, base, &contacts);
  f.corrected = std::move(r.corrected);
  f.correction = std::move(r.rotation);
  f.shift_m = std::move(r.shift_m);
  f.follow = std::move(r.follow);
  f.drop_m = std::move(r.drop_m);
  f.arm_swing_rad = std::move(r.arm_swing_rad);
  f.max_arm_swing_rad = r.max_arm_swing_rad;
  f.unsolved = std::move(r.unsolved);
  f.frames_unsolved = r.frames_unsolved;
  f.max_foot_displacement_m = r.max_foot_displacement_m;
  f.max_drop_m = r.max_drop_m;
  f.iterations = r.iterations;
  f.operator_band = r.lookahead_frames;
  return f;
}

// The streaming filter run over the clip frame by frame, in the report's
// shape; its cost per frame goes to `cost_us` (mean, max).
bool online_result(const balance::HumanMotion& motion, const balance::AnalysisOptions& base,
                   const ZmpCommandOptions& opt, balance::FilterResult& f, std::array<double, 2>& cost_us,
                   std::string& error) {
  balance::OnlineOptions oo;
  oo.analysis = base;
  oo.dt_s = motion.dt_s;
  oo.lookahead_s = opt.lookahead_s;
  if (opt.margin_m > 0.0) oo.margin_m = opt.margin_m;  // else the filter's own, as tonusd runs it
  oo.constraint_weight = opt.plan_weight;
  oo.window_cutoff_hz = opt.window_cutoff_hz;
  balance::OnlineRun run = balance::run_online(motion, oo);
  if (!run.ok()) {
    error = run.error;
    return false;
  }
  f.corrected = std::move(run.corrected);
  f.correction.assign(motion.size(), balance::Vec3::Zero());
  f.shift_m = std::move(run.shift_m);
  f.drop_m = std::move(run.drop_m);
  f.unsolved.assign(motion.size(), false);
  f.max_drop_m = run.max_drop_m;
  cost_us = {run.mean_push_us, run.max_push_us};
  f.before = balance::analyse(motion, base);
  f.after = balance::analyse(f.corrected, base, &f.before.contacts);
  f.operator_band = run.lookahead_frames;
  return true;
}

}  // namespace

int run_zmp_command(const ZmpCommandOptions& opt) {
  const auto fail = [](const std::string& message) {
    fmt::print(stderr, "tonus zmp: {}\n", message);
    return 2;
  };
  motion::ReadResult read = motion::read_bvh_file(opt.input);
  if (!read.ok()) {
    // (fmt, not string concatenation: GCC 12 sees a false -Wrestrict in "x" + std::string.)
    const std::string where = read.error->line > 0 ? fmt::format("{}:{}", opt.input, read.error->line) : opt.input;
    return fail(fmt::format("{}: {}", where, read.error->message));
  }
  std::string mapping_text;
  if (!opt.mapping.empty()) {
    std::ifstream in(opt.mapping);
    if (!in) return fail("cannot read the mapping file " + opt.mapping);
    std::stringstream ss;
    ss << in.rdbuf();
    mapping_text = ss.str();
  }
  const balance::MapResult mapping = balance::map_skeleton(read.clip, mapping_text);
  if (!mapping.ok()) return fail(mapping.error);
  balance::ConvertOptions convert;
  std::string error;
  if (!parse_unit(opt.unit, convert.metres_per_unit, error)) return fail(error);
  convert.exclude_tpose = !opt.keep_tpose;
  const balance::Conversion conv = balance::convert_motion(read.clip, mapping, convert);
  if (!conv.ok()) return fail(conv.error);

  balance::FilterOptions fo;
  balance::AnalysisOptions& ao = fo.analysis;
  if (!(opt.body_mass_kg > 0.0)) return fail("--mass must be positive");
  ao.body_mass_kg = opt.body_mass_kg;
  if (opt.sex != "male" && opt.sex != "female") return fail("--sex: male or female");
  ao.sex = opt.sex == "male" ? sim::Sex::male : sim::Sex::female;
  if (opt.trunk != "spine" && opt.trunk != "straight") return fail("--trunk: spine or straight");
  ao.trunk = opt.trunk == "spine" ? balance::TrunkModel::spine : balance::TrunkModel::straight;
  ao.angular_momentum = opt.full_zmp;
  if (!parse_method(opt.derivative, ao.derivatives.method)) {
    return fail("--derivative: kalman_spline, kalman, spline or finite_difference");
  }
  ao.derivatives.cutoff_hz = opt.cutoff_hz;
  if (const derivatives::Status s = derivatives::validate(ao.derivatives, conv.motion.dt_s, conv.motion.size()); !s) {
    return fail("derivatives: " + std::string(derivatives::to_string(s.error)));
  }
  ao.contacts.height_on_m = opt.contact_height_m;
  ao.contacts.height_off_m = 1.6 * opt.contact_height_m;
  ao.contacts.speed_on_mps = opt.contact_speed_mps;
  ao.contacts.speed_off_mps = 2.0 * opt.contact_speed_mps;
  ao.contacts.foot_length_m = opt.foot_length_m;
  ao.contacts.ground_z_m = opt.ground_height_m;
  if (opt.correction != "rotation" && opt.correction != "waist") return fail("--correction: rotation or waist");
  if (opt.margin_m >= 0.0) fo.margin_m = opt.margin_m;
  fo.max_correction_rad = opt.max_correction_rad;
  fo.max_iterations = opt.max_iterations;

  if (!opt.quiet) {
    fmt::print("tonus zmp: {}\n", opt.input);
    fmt::print("  skeleton: {} ({} joints), {} frames at {:.0f} Hz, unit {}{}\n", mapping.map.convention,
               read.clip.joints.size(), read.clip.frame_count, 1.0 / read.clip.frame_time_s, conv.unit_name,
               conv.unit_guessed ? " (guessed)" : "");
    std::string bones;
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      const int j = mapping.map.joint[b];
      bones += fmt::format("{}{} = {}", b == 0 ? "" : ", ", sim::kBones[b].name,
                           j < 0 ? std::string("(synthesised)") : read.clip.joints[static_cast<std::size_t>(j)].name);
    }
    fmt::print("  bones: {}\n", bones);
    for (const std::string& m : conv.messages) fmt::print("  note: {}\n", m);
    for (const auto& w : read.warnings) fmt::print("  warning (line {}): {}\n", w.line, w.message);
  }
  Progress progress{!opt.quiet && (isatty(STDERR_FILENO) != 0 || conv.motion.size() > 1000)};
  balance::FilterResult result;
  std::vector<balance::Vec2> shift_m;
  std::array<double, 2> online_cost_us{};
  if (opt.online) {
    if (!online_result(conv.motion, ao, opt, result, online_cost_us, error)) return fail("--online: " + error);
    shift_m = result.shift_m;
  } else if (opt.correction == "waist") {
    balance::RobustFilterOptions ro;
    ro.analysis = ao;
    if (opt.margin_m >= 0.0) ro.margin_m = opt.margin_m;
    ro.max_iterations = opt.max_iterations;
    ro.both_trunks = opt.both_trunks;
    ro.max_arm_swing_rad = opt.max_arm_swing_rad;
    ro.arm_weight = opt.arm_weight;
    balance::RobustFilterResult robust = balance::robust_balance_filter(conv.motion, ro, on_progress, &progress);
    if (progress.show) fmt::print(stderr, "\n");
    if (!robust.ok()) return fail(robust.error);
    result = as_filter_result(std::move(robust), conv.motion, ao);
    shift_m = std::move(result.shift_m);
  } else {
    result = balance::balance_filter(conv.motion, fo, on_progress, &progress);
    if (progress.show) fmt::print(stderr, "\n");
  }
  if (!result.ok()) return fail(result.error);

  balance::AppliedCorrection applied =
      balance::apply_correction(read.clip, conv.geometry, conv.motion, result.correction, shift_m, result.follow,
                                result.drop_m, result.arm_swing_rad);
  if (!applied.ok()) return fail(applied.error);
  if (!opt.output.empty()) {
    std::ofstream out(opt.output, std::ios::binary);
    out << motion::write_bvh(applied.clip, 6);
    if (!out) return fail("cannot write " + opt.output);
  }

  // The original and the written clip, read back as a user would, under every
  // estimator of the family: the filter's own figures are one member's.
  const std::vector<balance::AnalysisOptions> members = balance::estimator_family(ao, opt.both_trunks);
  const balance::FamilyVerdict family_before =
      balance::family_verdict(balance::analyse_family(conv.motion, members, result.before.contacts), members);
  const balance::Conversion written = balance::convert_motion(applied.clip, mapping, convert);
  if (!written.ok()) return fail("re-reading the corrected clip: " + written.error);
  const balance::ContactTrack written_contacts = balance::detect_contacts(written.motion, ao.contacts);
  const balance::FamilyVerdict family_after =
      balance::family_verdict(balance::analyse_family(written.motion, members, written_contacts), members);

  ZmpReport report;
  report.family_before = &family_before;
  report.family_after = &family_after;
  report.input = opt.input;
  report.convention = mapping.map.convention;
  report.unit = conv.unit_name;
  report.unit_guessed = conv.unit_guessed;
  report.tpose_excluded = conv.tpose_excluded;
  report.frame_time_s = read.clip.frame_time_s;
  report.frames_total = read.clip.frame_count;
  report.filter = &result;
  report.applied = &applied;
  for (const balance::Vec3& d : result.correction)
    report.max_correction_rad = std::max(report.max_correction_rad, d.norm());
  report.lookahead_frames = result.operator_band;
  report.online = opt.online;
  report.online_mean_us = online_cost_us[0];
  report.online_max_us = online_cost_us[1];
  report.online_window_cutoff_hz = opt.window_cutoff_hz;
  report.forward = travel_direction(conv.motion, result.before);
  if (!opt.csv.empty() && !write_zmp_csv(opt.csv, report, error)) return fail(error);
  if (!opt.json.empty() && !write_zmp_json(opt.json, report, error)) return fail(error);
  if (!opt.svg.empty() && !write_zmp_svg(opt.svg, report, error)) return fail(error);

  const balance::AnalysisSummary& b = result.before.summary;
  const balance::AnalysisSummary& a = result.after.summary;
  if (!opt.quiet) {
    std::size_t both = 0, left = 0, right = 0;
    for (std::size_t t = conv.motion.first_frame; t < conv.motion.size(); ++t) {
      const auto& c = result.before.contacts.frames[t];
      if (c[0].any() && c[1].any())
        ++both;
      else if (c[0].any())
        ++left;
      else if (c[1].any())
        ++right;
    }
    fmt::print("  contacts: {} frames double support, {} left foot only, {} right foot only, {} airborne\n", both, left,
               right, b.frames_airborne);
    fmt::print("  before: ZMP outside the support polygon in {} of {} frames (max {:.3f} m, RMS {:.3f} m)\n",
               b.frames_outside, b.frames, b.max_outside_m, b.rms_outside_m);
    fmt::print("  after:  ZMP outside the support polygon in {} of {} frames (max {:.3f} m), {} unsolved\n",
               a.frames_outside, a.frames, a.max_outside_m, result.frames_unsolved);
    if (opt.online) {
      double shift = 0.0;
      for (const balance::Vec2& s : shift_m) shift = std::max(shift, s.norm());
      fmt::print(
          "  correction (online, look-ahead {:.3f} s = {} frames, window smoothing {:g} Hz): pelvis shift up to {:.1f} "
          "cm, lowered up to {:.1f} mm; feet down moved by at most {:.2e} m; {:.0f} us per frame (max {:.0f} us)\n",
          opt.lookahead_s, result.operator_band, opt.window_cutoff_hz, 100.0 * shift, 1000.0 * result.max_drop_m,
          applied.max_foot_displacement_m, online_cost_us[0], online_cost_us[1]);
    } else if (shift_m.empty()) {
      fmt::print("  correction: waist rotation up to {:.3f} rad, feet moved by at most {:.2e} m, {} iterations\n",
                 report.max_correction_rad, applied.max_foot_displacement_m, result.iterations);
    } else {
      double lean = 0.0, yaw = 0.0, shift = 0.0;
      for (std::size_t t = 0; t < shift_m.size(); ++t) {
        lean = std::max(lean, result.correction[t].head<2>().norm());
        yaw = std::max(yaw, std::abs(result.correction[t].z()));
        shift = std::max(shift, shift_m[t].norm());
      }
      fmt::print(
          "  correction: lean up to {:.1f} deg, yaw up to {:.1f} deg, pelvis shift up to {:.1f} cm, lowered up to "
          "{:.1f} mm, arms swung up to {:.1f} deg; feet down moved by at most {:.2e} m, feet in the air followed the "
          "pelvis by up to {:.1f} cm; {} iterations\n",
          lean * 180.0 / M_PI, yaw * 180.0 / M_PI, 100.0 * shift, 1000.0 * result.max_drop_m,
          result.max_arm_swing_rad * 180.0 / M_PI, applied.max_foot_displacement_m,
          100.0 * applied.max_swing_foot_displacement_m, result.iterations);
    }
    // Only the joints and frames changed count, so the figure is the edit's real size.
    std::string largest;
    for (const balance::JointChange& c : applied.largest_change) {
      largest += fmt::format("{}{} {:.3f}{} (frame {})", largest.empty() ? "" : ", ", c.joint, c.max_rad,
                             largest.empty() ? " rad" : "", c.frame);
    }
    if (largest.empty()) {
      fmt::print("  joint change: none\n");
    } else {
      fmt::print(
          "  joint change: RMS change over changed joints {:.4f} rad ({} joints, {} joint-frames), largest per "
          "joint: {}\n",
          applied.rms_change_changed_joints_rad, applied.largest_change.size(), applied.changed_samples, largest);
    }
    print_family(family_before, family_after);
    if (result.frames_unsolved > 0) {
      std::string list;
      std::size_t shown = 0;
      for (std::size_t t = 0; t < result.unsolved.size() && shown < 12; ++t) {
        if (!result.unsolved[t]) continue;
        list += (shown++ > 0 ? ", " : "") + std::to_string(t);
      }
      if (shift_m.empty()) {
        fmt::print("  unsolved frames (no correction within {:.2f} rad, or a leg out of reach): {}{}\n",
                   opt.max_correction_rad, list, result.frames_unsolved > shown ? ", ..." : "");
      } else {
        fmt::print("  frames outside by more than {:.0f} cm under some estimator: {}{}\n",
                   100.0 * balance::kFamilyThreshold_m, list, result.frames_unsolved > shown ? ", ..." : "");
      }
    }
    if (!opt.output.empty()) fmt::print("  written: {}\n", opt.output);
  }
  // The waist correction answers to the family: a few frames outside under
  // some member are allowed (kFamilyAllowedShare), a clip that is not
  // balanced under every member is not.
  if (!shift_m.empty()) return family_after.balanced() ? 0 : 1;
  return result.frames_unsolved == 0 ? 0 : 1;
}

}  // namespace tonus::tools
