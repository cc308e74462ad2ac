#include "tonus/host/balance/family.hpp"

#include <array>
#include <optional>

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

std::vector<AnalysisOptions> estimator_family(const AnalysisOptions& base, bool both_trunks) {
  std::vector<AnalysisOptions> members = estimator_family(base);
  if (!both_trunks) return members;
  AnalysisOptions other = base;
  other.trunk = base.trunk == TrunkModel::spine ? TrunkModel::straight : TrunkModel::spine;
  for (const AnalysisOptions& o : estimator_family(other)) members.push_back(o);
  return members;
}

std::vector<Analysis> analyse_family(const HumanMotion& motion, const std::vector<AnalysisOptions>& members,
                                     const ContactTrack& contacts) {
  std::vector<Analysis> out(members.size());
  if (members.empty()) return out;
  // The segments are placed once per trunk model (the first member's body).
  std::array<std::optional<Analysis>, 2> placed;
  const auto placed_for = [&](TrunkModel trunk) -> const Analysis& {
    std::optional<Analysis>& slot = placed[trunk == TrunkModel::spine ? 0 : 1];
    if (!slot) {
      AnalysisOptions o = members.front();
      o.trunk = trunk;
      detail::place_all_segments(slot.emplace(), motion, o, &contacts);
    }
    return *slot;
  };
  const auto same_group = [&](std::size_t i, std::size_t j) {
    return members[j].trunk == members[i].trunk && same_derivatives(members[j].derivatives, members[i].derivatives);
  };
  std::vector<bool> done(members.size(), false);
  std::vector<Vec3> ang_rate;
  for (std::size_t i = 0; i < members.size(); ++i) {
    if (done[i]) continue;
    // One differentiation serves every member with these derivatives and
    // this trunk; the angular momentum is differentiated if any of them needs it.
    bool angular = false;
    for (std::size_t j = i; j < members.size(); ++j) {
      if (same_group(i, j)) angular |= members[j].angular_momentum;
    }
    Analysis diff = placed_for(members[i].trunk);
    if (!detail::differentiate_segments(diff, motion, members[i].derivatives, angular, ang_rate)) {
      for (Analysis& a : out) a = diff;  // the same refusal for everyone
      return out;
    }
    const std::vector<Vec3> none(ang_rate.size(), Vec3::Zero());
    for (std::size_t j = i; j < members.size(); ++j) {
      if (done[j] || !same_group(i, j)) continue;
      out[j] = diff;
      if (members[j].body_mass_kg != members.front().body_mass_kg || members[j].sex != members.front().sex) {
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
