#include "tonus/host/balance/analysis.hpp"

#include <cmath>

#include "analysis_parts.hpp"
#include "tonus/host/balance/zmp.hpp"
#include "tonus/host/derivatives/batch.hpp"

namespace tonus::balance {

namespace detail {

void place_all_segments(Analysis& a, const HumanMotion& motion, const AnalysisOptions& opt,
                        const ContactTrack* contacts) {
  a.mass = make_mass_model(opt.body_mass_kg, opt.sex, opt.trunk);
  a.contacts = contacts != nullptr ? *contacts : detect_contacts(motion, opt.contacts);
  const std::size_t n = motion.size();
  a.frames.assign(n, {});
  a.segments.assign(n, {});
  a.accelerations.assign(n, {});
  for (std::size_t t = 0; t < n; ++t) a.segments[t] = place_segments(a.mass, motion.frames[t].p);
}

bool differentiate_segments(Analysis& a, const HumanMotion& motion, const derivatives::Params& params, bool angular,
                            std::vector<Vec3>& ang_rate) {
  const std::size_t n = motion.size(), first = motion.first_frame;
  ang_rate.assign(n, Vec3::Zero());
  if (n < first + derivatives::kMinSamples) {
    a.error = "too few frames to differentiate (" + std::to_string(n - first) + ")";
    return false;
  }
  const std::size_t m = n - first;
  // Accelerations of every segment's centre of mass (and, for the full form, the
  // rate of its angular momentum), by the derivatives library.
  std::vector<Vec3> series(m);
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    for (std::size_t t = 0; t < m; ++t) series[t] = a.segments[first + t][i].com;
    const derivatives::Result3 r = derivatives::differentiate(series, motion.dt_s, params);
    if (!r) {
      a.error =
          "differentiating segment " + std::to_string(i) + ": " + std::string(derivatives::to_string(r.status.error));
      return false;
    }
    for (std::size_t t = 0; t < m; ++t) a.accelerations[first + t][i] = r.acc[t];
    if (angular) {
      for (std::size_t t = 0; t < m; ++t) series[t] = a.segments[first + t][i].axis;
      const derivatives::Result3 axis = derivatives::differentiate(series, motion.dt_s, params);
      if (!axis) continue;
      for (std::size_t t = 0; t < m; ++t)
        series[t] = segment_angular_momentum(a.mass, i, a.segments[first + t][i], axis.vel[t]);
      const derivatives::Result3 l = derivatives::differentiate(series, motion.dt_s, params);
      if (!l) continue;
      for (std::size_t t = 0; t < m; ++t) ang_rate[first + t] += l.vel[t];
    }
  }
  return true;
}

void evaluate_frames(Analysis& a, const HumanMotion& motion, const AnalysisOptions& opt,
                     const std::vector<Vec3>& ang_rate) {
  const std::size_t n = motion.size(), first = motion.first_frame;
  a.angular_momentum_rate = ang_rate;
  AnalysisSummary& s = a.summary;
  s = {};
  double sum_sq = 0.0;
  for (std::size_t t = first; t < n; ++t) {
    FrameAnalysis& f = a.frames[t];
    f = {};
    f.analysed = true;
    ++s.frames;
    f.com = centre_of_mass(a.mass, a.segments[t]);
    ZmpInputs in;
    in.segments = &a.segments[t];
    in.accel = &a.accelerations[t];
    in.angular_momentum_rate = ang_rate[t];
    const ZmpResult z = zero_moment_point(a.mass, in, a.contacts.ground_z_m, opt.gravity);
    f.zmp_defined = z.defined;
    f.zmp = z.zmp;
    f.support = support_polygon(a.contacts, motion.frames[t], t);
    f.airborne = f.support.empty();
    if (f.airborne) {
      ++s.frames_airborne;
      continue;
    }
    if (!f.zmp_defined) {
      ++s.frames_undefined;
      continue;
    }
    f.outside_m = signed_distance(f.support, f.zmp);
    if (f.outside_m > opt.tolerance_m) {
      ++s.frames_outside;
      sum_sq += f.outside_m * f.outside_m;
      s.max_outside_m = std::max(s.max_outside_m, f.outside_m);
    }
  }
  s.rms_outside_m = s.frames_outside > 0 ? std::sqrt(sum_sq / static_cast<double>(s.frames_outside)) : 0.0;
}

}  // namespace detail

Analysis analyse(const HumanMotion& motion, const AnalysisOptions& opt, const ContactTrack* contacts) {
  Analysis a;
  detail::place_all_segments(a, motion, opt, contacts);
  std::vector<Vec3> ang_rate;
  if (!detail::differentiate_segments(a, motion, opt.derivatives, opt.angular_momentum, ang_rate)) return a;
  detail::evaluate_frames(a, motion, opt, ang_rate);
  return a;
}

}  // namespace tonus::balance
