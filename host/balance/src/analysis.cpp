#include "tonus/host/balance/analysis.hpp"

#include <cmath>

#include "tonus/host/balance/zmp.hpp"
#include "tonus/host/derivatives/batch.hpp"

namespace tonus::balance {

Analysis analyse(const HumanMotion& motion, const AnalysisOptions& opt, const ContactTrack* contacts) {
  Analysis a;
  a.mass = make_mass_model(opt.body_mass_kg, opt.sex);
  a.contacts = contacts != nullptr ? *contacts : detect_contacts(motion, opt.contacts);
  const std::size_t n = motion.size(), first = motion.first_frame;
  a.frames.assign(n, {});
  a.segments.assign(n, {});
  a.accelerations.assign(n, {});
  for (std::size_t t = 0; t < n; ++t) a.segments[t] = place_segments(a.mass, motion.frames[t].p);
  if (n < first + derivatives::kMinSamples) {
    a.error = "too few frames to differentiate (" + std::to_string(n - first) + ")";
    return a;
  }
  const std::size_t m = n - first;
  // Accelerations of every segment's centre of mass (and, for the full form, the
  // rate of its angular momentum), by the derivatives library.
  std::vector<Vec3> series(m);
  std::vector<Vec3> ang_rate(n, Vec3::Zero());
  std::vector<Vec3> axis_rate;
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    for (std::size_t t = 0; t < m; ++t) series[t] = a.segments[first + t][i].com;
    const derivatives::Result3 r = derivatives::differentiate(series, motion.dt_s, opt.derivatives);
    if (!r) {
      a.error =
          "differentiating segment " + std::to_string(i) + ": " + std::string(derivatives::to_string(r.status.error));
      return a;
    }
    for (std::size_t t = 0; t < m; ++t) a.accelerations[first + t][i] = r.acc[t];
    if (opt.angular_momentum) {
      for (std::size_t t = 0; t < m; ++t) series[t] = a.segments[first + t][i].axis;
      const derivatives::Result3 axis = derivatives::differentiate(series, motion.dt_s, opt.derivatives);
      if (!axis) continue;
      for (std::size_t t = 0; t < m; ++t)
        series[t] = segment_angular_momentum(a.mass, i, a.segments[first + t][i], axis.vel[t]);
      const derivatives::Result3 l = derivatives::differentiate(series, motion.dt_s, opt.derivatives);
      if (!l) continue;
      for (std::size_t t = 0; t < m; ++t) ang_rate[first + t] += l.vel[t];
    }
  }

  AnalysisSummary& s = a.summary;
  double sum_sq = 0.0;
  for (std::size_t t = first; t < n; ++t) {
    FrameAnalysis& f = a.frames[t];
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
  return a;
}

}  // namespace tonus::balance
