#include "zmp_outputs.hpp"

#include <fmt/core.h>
#include <fmt/os.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace tonus::tools {
namespace {

using balance::Vec2;

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

// Writes `text` to `path`, reporting failure instead of throwing.
bool write_file(const std::string& path, const std::string& text, std::string& error) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    error = "cannot write " + path;
    return false;
  }
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) error = "cannot write " + path;
  return ok && closed;
}

}  // namespace

Vec2 travel_direction(const balance::HumanMotion& motion, const balance::Analysis& analysis) {
  const std::size_t first = motion.first_frame;
  if (first < analysis.frames.size()) {
    const Vec2 a = analysis.frames[first].com.head<2>(), b = analysis.frames.back().com.head<2>();
    if ((b - a).norm() > 0.5) return (b - a).normalized();
    // In place: the way the body faces (left hip to right hip, turned a quarter).
    const auto& p = motion.frames[first].p;
    const balance::Vec3 left = p[sim::index(sim::Bone::LeftUpperLeg)] - p[sim::index(sim::Bone::RightUpperLeg)];
    const Vec2 facing(left.y(), -left.x());
    if (facing.norm() > 1e-9) return facing.normalized();
  }
  return Vec2::UnitX();
}

bool write_zmp_csv(const std::string& path, const ZmpReport& r, std::string& error) {
  const balance::FilterResult& f = *r.filter;
  std::string out =
      "frame,time_s,analysed,airborne,left_contact,right_contact,zmp_x_before_m,zmp_y_before_m,zmp_x_after_m,"
      "zmp_y_after_m,outside_before_m,outside_after_m,com_x_m,com_y_m,com_z_m,correction_rad,unsolved\n";
  for (std::size_t t = 0; t < f.before.frames.size(); ++t) {
    const auto& b = f.before.frames[t];
    const auto& a = f.after.frames[t];
    const auto contact = [&](std::size_t foot) {
      const auto& c = f.before.contacts.frames[t][foot];
      return c.heel && c.ball ? "flat" : (c.heel ? "heel" : (c.ball ? "ball" : "none"));
    };
    const auto num = [](bool defined, double v) { return defined ? fmt::format("{:.6f}", v) : std::string(); };
    const bool zb = b.analysed && b.zmp_defined, za = a.analysed && a.zmp_defined;
    const bool ob = zb && !b.airborne, oa = za && !a.airborne;
    out += fmt::format("{},{:.6f},{},{},{},{},{},{},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{}\n", t,
                       static_cast<double>(t) * r.frame_time_s, b.analysed ? 1 : 0, b.airborne ? 1 : 0, contact(0),
                       contact(1), num(zb, b.zmp.x()), num(zb, b.zmp.y()), num(za, a.zmp.x()), num(za, a.zmp.y()),
                       num(ob, b.outside_m), num(oa, a.outside_m), a.com.x(), a.com.y(), a.com.z(),
                       f.correction[t].norm(), f.unsolved.empty() ? 0 : (f.unsolved[t] ? 1 : 0));
  }
  return write_file(path, out, error);
}

// Each member's verdict before and after, and the worst one's share after.
std::string family_json(const balance::FamilyVerdict* before, const balance::FamilyVerdict* after) {
  if (before == nullptr || after == nullptr) return "  \"estimators\": []\n";
  std::string out = fmt::format("  \"estimator_threshold_m\": {:.3f},\n", after->threshold_m);
  out += "  \"estimators\": [";
  for (std::size_t i = 0; i < after->members.size() && i < before->members.size(); ++i) {
    const balance::MemberVerdict& b = before->members[i];
    const balance::MemberVerdict& a = after->members[i];
    out += fmt::format(
        "{}\n    {{\"cutoff_hz\": {}, \"form\": \"{}\", \"trunk\": \"{}\", \"supported_frames\": {}, "
        "\"outside_before\": {}, \"outside_after\": {}, \"max_outside_before_m\": {:.6f}, \"max_outside_after_m\": "
        "{:.6f}}}",
        i == 0 ? "" : ",", a.cutoff_hz, a.full ? "full" : "particle",
        a.trunk == balance::TrunkModel::straight ? "straight" : "spine", a.supported, b.outside, a.outside,
        b.max_outside_m, a.max_outside_m);
  }
  out += after->members.empty() ? "],\n" : "\n  ],\n";
  const double worst = after->members.empty() ? 0.0 : after->members[after->worst].share();
  out += fmt::format("  \"worst_estimator_share_outside_after\": {:.6f},\n", worst);
  out += fmt::format("  \"balanced_under_every_estimator\": {}\n", after->balanced());
  return out;
}

bool write_zmp_json(const std::string& path, const ZmpReport& r, std::string& error) {
  const balance::FilterResult& f = *r.filter;
  const balance::AnalysisSummary& b = f.before.summary;
  const balance::AnalysisSummary& a = f.after.summary;
  std::string out = "{\n";
  out += fmt::format("  \"input\": {},\n", json_string(r.input));
  out += fmt::format("  \"skeleton\": {},\n", json_string(r.convention));
  out += fmt::format("  \"unit\": {},\n  \"unit_guessed\": {},\n", json_string(r.unit), r.unit_guessed);
  out += fmt::format("  \"frame_time_s\": {},\n  \"frames_total\": {},\n", r.frame_time_s, r.frames_total);
  out += fmt::format("  \"tpose_excluded\": {},\n", r.tpose_excluded);
  out += fmt::format("  \"frames\": {},\n", b.frames);
  out += fmt::format("  \"frames_outside_before\": {},\n  \"frames_outside_after\": {},\n", b.frames_outside,
                     a.frames_outside);
  out += fmt::format("  \"max_outside_before_m\": {:.6f},\n  \"max_outside_after_m\": {:.6f},\n", b.max_outside_m,
                     a.max_outside_m);
  out += fmt::format("  \"rms_outside_before_m\": {:.6f},\n  \"rms_outside_after_m\": {:.6f},\n", b.rms_outside_m,
                     a.rms_outside_m);
  const balance::AppliedCorrection& w = *r.applied;
  out += fmt::format("  \"max_foot_displacement_m\": {:.9f},\n", w.max_foot_displacement_m);
  out += fmt::format("  \"max_pelvis_drop_m\": {:.6f},\n", f.max_drop_m);
  out += fmt::format("  \"max_arm_swing_rad\": {:.6f},\n", f.max_arm_swing_rad);
  // rms_joint_change_rad is the older all-mapped-joints figure, kept for existing readers.
  out += fmt::format("  \"rms_joint_change_rad\": {:.6f},\n", w.rms_change_all_mapped_joints_rad);
  out += fmt::format("  \"rms_change_changed_joints_rad\": {:.6f},\n", w.rms_change_changed_joints_rad);
  out += fmt::format("  \"changed_joints\": {},\n  \"changed_joint_frames\": {},\n", w.largest_change.size(),
                     w.changed_samples);
  out += "  \"max_change_per_joint\": {";
  for (std::size_t i = 0; i < w.largest_change.size(); ++i) {
    const balance::JointChange& c = w.largest_change[i];
    out += fmt::format("{}\n    {}: {{\"bone\": {}, \"max_rad\": {:.6f}, \"frame\": {}}}", i == 0 ? "" : ",",
                       json_string(c.joint), json_string(c.bone), c.max_rad, c.frame);
  }
  out += w.largest_change.empty() ? "},\n" : "\n  },\n";
  out += fmt::format("  \"max_correction_rad\": {:.6f},\n", r.max_correction_rad);
  out += fmt::format("  \"frames_unsolved\": {},\n", f.frames_unsolved);
  out += fmt::format("  \"frames_airborne\": {},\n", b.frames_airborne);
  out += fmt::format("  \"frames_zmp_undefined\": {},\n", b.frames_undefined);
  out += fmt::format("  \"iterations\": {},\n", f.iterations);
  out += fmt::format("  \"lookahead_frames\": {},\n", r.lookahead_frames);
  out += fmt::format("  \"online\": {},\n", r.online ? "true" : "false");
  if (r.online) {
    out += fmt::format("  \"online_us_per_frame\": {{\"mean\": {:.1f}, \"max\": {:.1f}}},\n", r.online_mean_us,
                       r.online_max_us);
    out += fmt::format("  \"online_window_cutoff_hz\": {},\n", r.online_window_cutoff_hz);
  }
  out += family_json(r.family_before, r.family_after);
  out += "}\n";
  return write_file(path, out, error);
}

bool write_zmp_svg(const std::string& path, const ZmpReport& r, std::string& error) {
  const balance::FilterResult& f = *r.filter;
  const Vec2 fwd = r.forward, lat(-r.forward.y(), r.forward.x());
  const std::size_t n = f.before.frames.size();
  const double width = 960, panel = 260, left = 70, right = 20, top = 40, gap = 50;
  const double t_end = std::max(1e-9, static_cast<double>(n) * r.frame_time_s);
  const auto tx = [&](double t) { return left + (width - left - right) * t / t_end; };
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" font-family=\"sans-serif\" "
      "font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      width, top + 2 * panel + gap + 40);
  svg += fmt::format(
      "<text x=\"{}\" y=\"20\" font-size=\"14\">ZMP before (red) and after (blue) the balance filter, "
      "support polygon extent shaded, airborne frames yellow: {}</text>\n",
      left, r.input);
  for (int k = 0; k < 2; ++k) {
    const Vec2 axis = k == 0 ? fwd : lat;
    const double y0 = top + k * (panel + gap);
    // Along the travel, positions are shown relative to the centre of mass (a
    // walk covers metres, its ZMP excursions centimetres); laterally as they are.
    const auto offset = [&](std::size_t t) { return k == 0 ? f.before.frames[t].com.head<2>().dot(axis) : 0.0; };
    // Range of the panel: support extents and ZMPs.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t t = 0; t < n; ++t) {
      const auto& fb = f.before.frames[t];
      if (!fb.analysed) continue;
      for (const Vec2& v : fb.support.vertices) {
        lo = std::min(lo, v.dot(axis) - offset(t));
        hi = std::max(hi, v.dot(axis) - offset(t));
      }
      lo = std::min(lo, fb.com.head<2>().dot(axis) - offset(t));
      hi = std::max(hi, fb.com.head<2>().dot(axis) - offset(t));
      for (const auto* fr : {&fb, &f.after.frames[t]}) {
        if (!fr->zmp_defined || fr->airborne) continue;
        lo = std::min(lo, fr->zmp.dot(axis) - offset(t));
        hi = std::max(hi, fr->zmp.dot(axis) - offset(t));
      }
    }
    if (!std::isfinite(lo)) lo = -1, hi = 1;
    const double pad = 0.05 * (hi - lo) + 1e-3;
    lo -= pad;
    hi += pad;
    const auto ty = [&](double v) { return y0 + panel * (1.0 - (v - lo) / (hi - lo)); };
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#888\"/>\n", left, y0,
                       width - left - right, panel);
    svg += fmt::format("<text x=\"{}\" y=\"{}\">{} (m)</text>\n", left, y0 - 6,
                       k == 0 ? "along the direction of travel, relative to the centre of mass" : "lateral");
    const double w = tx(r.frame_time_s) - tx(0.0) + 0.3;
    for (std::size_t t = 0; t < n; ++t) {
      const auto& fb = f.before.frames[t];
      if (!fb.analysed) continue;
      const double x = tx(static_cast<double>(t) * r.frame_time_s);
      if (fb.airborne) {
        svg += fmt::format("<rect x=\"{:.2f}\" y=\"{}\" width=\"{:.2f}\" height=\"{}\" fill=\"#fff3b0\"/>\n", x, y0, w,
                           panel);
        continue;
      }
      double a = std::numeric_limits<double>::infinity(), b = -a;
      for (const Vec2& v : fb.support.vertices) {
        a = std::min(a, v.dot(axis) - offset(t));
        b = std::max(b, v.dot(axis) - offset(t));
      }
      svg += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" fill=\"#cfe3cf\"/>\n", x,
                         ty(b), w, std::max(ty(a) - ty(b), 0.5));
    }
    const auto polyline = [&](const char* colour, bool after, bool com) {
      std::string pts;
      std::string out;
      for (std::size_t t = 0; t < n; ++t) {
        const auto& fr = after ? f.after.frames[t] : f.before.frames[t];
        const bool ok = fr.analysed && (com || (fr.zmp_defined && !fr.airborne));
        if (!ok) {
          if (!pts.empty())
            out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\"{} points=\"{}\"/>\n", colour,
                               com ? " stroke-dasharray=\"4 3\"" : "", pts);
          pts.clear();
          continue;
        }
        const double v = (com ? fr.com.head<2>().dot(axis) : fr.zmp.dot(axis)) - offset(t);
        pts += fmt::format("{:.2f},{:.2f} ", tx(static_cast<double>(t) * r.frame_time_s), ty(v));
      }
      if (!pts.empty())
        out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\"{} points=\"{}\"/>\n", colour,
                           com ? " stroke-dasharray=\"4 3\"" : "", pts);
      return out;
    };
    svg += polyline("#888888", false, true);
    svg += polyline("#d62728", false, false);
    svg += polyline("#1f4fb4", true, false);
    for (int tick = 0; tick <= 4; ++tick) {
      const double v = lo + (hi - lo) * tick / 4.0;
      svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{:.2f}</text>\n", left - 6, ty(v) + 4, v);
    }
  }
  const double base = top + 2 * panel + gap;
  for (int tick = 0; tick <= 5; ++tick) {
    const double t = t_end * tick / 5.0;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{:.1f} s</text>\n", tx(t), base + 16, t);
  }
  svg += fmt::format(
      "<text x=\"{}\" y=\"{}\">red: ZMP before, blue: after, grey dashed: centre of mass, green: "
      "support polygon, yellow: airborne</text>\n",
      left, base + 34);
  svg += "</svg>\n";
  return write_file(path, svg, error);
}

}  // namespace tonus::tools
