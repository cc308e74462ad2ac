#include "tonus/host/balance/family.hpp"

#include "analysis_parts.hpp"

namespace tonus::balance {
namespace {

bool same_derivatives(const derivatives::Params& a, const derivatives::Params& b) {
  return a.method == b.method && a.cutoff_hz == b.cutoff_hz && a.noise_sigma == b.noise_sigma &&
         a.spline_end == b.spline_end && a.outlier_gate == b.outlier_gate;
}

}  // namespace

std::vector<AnalysisOptions> estimator_family(const AnalysisOptions& base) {
  std::vector<AnalysisOptions> members;
  for (const double cutoff : kFamilyCutoffsHz) {
    for (const bool full : {false, true}) {
      AnalysisOptions o = base;
      o.derivatives.cutoff_hz = cutoff;
      o.angular_momentum = full;
      members.push_back(o);
    }
  }
  return members;
}

std::vector<AnalysisOptions> estimator_family(const AnalysisOptions& base, std::span<const TrunkModel> trunks) {
  std::vector<AnalysisOptions> members;
  for (const TrunkModel trunk : trunks) {
    AnalysisOptions b = base;
    b.trunk = trunk;
    for (const AnalysisOptions& o : estimator_family(b)) members.push_back(o);
  }
  return members;
}

std::vector<Analysis> analyse_family(const HumanMotion& motion, const std::vector<AnalysisOptions>& members,
                                     const ContactTrack& contacts) {
  std::vector<Analysis> out(members.size());
  if (members.empty()) return out;
  Analysis placed;
  detail::place_all_segments(placed, motion, members.front(), &contacts);
  std::vector<bool> done(members.size(), false);
  std::vector<Vec3> ang_rate;
  for (std::size_t i = 0; i < members.size(); ++i) {
    if (done[i]) continue;
    // One differentiation serves every member with these derivatives; the
    // angular momentum is differentiated if any of them needs it.
    bool angular = false;
    for (std::size_t j = i; j < members.size(); ++j) {
      if (same_derivatives(members[j].derivatives, members[i].derivatives)) angular |= members[j].angular_momentum;
    }
    Analysis diff = placed;
    if (!detail::differentiate_segments(diff, motion, members[i].derivatives, angular, ang_rate)) {
      for (Analysis& a : out) a = diff;  // the same refusal for everyone
      return out;
    }
    const std::vector<Vec3> none(ang_rate.size(), Vec3::Zero());
    for (std::size_t j = i; j < members.size(); ++j) {
      if (done[j] || !same_derivatives(members[j].derivatives, members[i].derivatives)) continue;
      out[j] = diff;
      if (members[j].body_mass_kg != members.front().body_mass_kg || members[j].sex != members.front().sex ||
          members[j].trunk != members.front().trunk) {
        out[j] = analyse(motion, members[j], &contacts);  // another body: nothing to share
      } else {
        detail::evaluate_frames(out[j], motion, members[j], members[j].angular_momentum ? ang_rate : none);
      }
      done[j] = true;
    }
  }
  return out;
}

FamilyVerdict family_verdict(const std::vector<Analysis>& analyses, const std::vector<AnalysisOptions>& members,
                             double threshold_m) {
  FamilyVerdict v;
  v.threshold_m = threshold_m;
  for (std::size_t i = 0; i < analyses.size() && i < members.size(); ++i) {
    MemberVerdict mv;
    mv.cutoff_hz = members[i].derivatives.cutoff_hz;
    mv.full = members[i].angular_momentum;
    mv.trunk = members[i].trunk;
    for (const FrameAnalysis& f : analyses[i].frames) {
      if (!f.analysed || f.airborne || !f.zmp_defined) continue;
      ++mv.supported;
      if (f.outside_m > threshold_m) ++mv.outside;
      mv.max_outside_m = std::max(mv.max_outside_m, f.outside_m);
    }
    v.members.push_back(mv);
    if (mv.outside > v.members[v.worst].outside) v.worst = i;
  }
  return v;
}

}  // namespace tonus::balance
