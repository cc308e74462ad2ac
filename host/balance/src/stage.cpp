#include "tonus/host/balance/stage.hpp"

#include <exception>
#include <vector>

#include "tonus/host/balance/family.hpp"
#include "tonus/host/balance/robust_filter.hpp"

namespace tonus::balance {

std::string_view to_string(BalanceMode mode) {
  switch (mode) {
    case BalanceMode::off: return "off";
    case BalanceMode::offline: return "offline";
    case BalanceMode::online: return "online";
  }
  return "?";
}

BalanceStageResult balance_stage(const HumanMotion& motion, const BalanceStageOptions& options) {
  BalanceStageResult r;
  r.motion = motion;
  if (options.mode == BalanceMode::off) return r;
  try {
    const AnalysisOptions& analysis = options.analysis;
    Analysis before, after;
    FamilyVerdict family_after;
    if (options.mode == BalanceMode::offline) {
      RobustFilterOptions ro;
      ro.analysis = analysis;
      RobustFilterResult f = robust_balance_filter(motion, ro);
      if (!f.ok()) {
        r.error = "offline balance filter: " + f.error;
        return r;
      }
      r.motion = std::move(f.corrected);
      family_after = std::move(f.verdict_after);  // the filter analysed the family already
      // The base estimator is a member when its cut-off is one of the family's.
      bool found = false;
      for (std::size_t i = 0; i < f.members.size() && !found; ++i) {
        found = f.members[i].derivatives.cutoff_hz == analysis.derivatives.cutoff_hz &&
                f.members[i].angular_momentum == analysis.angular_momentum;
        if (found) {
          before = std::move(f.before[i]);
          after = std::move(f.after[i]);
        }
      }
      if (!found) {
        before = analyse(motion, analysis, &f.before.front().contacts);
        after = analyse(r.motion, analysis, &f.before.front().contacts);
      }
    } else {
      OnlineOptions oo;
      oo.analysis = analysis;
      oo.dt_s = motion.dt_s;
      oo.lookahead_s = options.lookahead_s;
      OnlineRun run = run_online(motion, oo);
      if (!run.ok()) {
        r.error = "online balance filter: " + run.error;
        return r;
      }
      r.motion = std::move(run.corrected);
      r.lookahead_frames = run.lookahead_frames;
      before = analyse(motion, analysis);
      if (!before.ok()) {
        r.error = "balance analysis: " + before.error;
        r.motion = motion;
        return r;
      }
      after = analyse(r.motion, analysis, &before.contacts);
      const std::vector<AnalysisOptions> members = estimator_family(analysis);
      family_after = family_verdict(analyse_family(r.motion, members, before.contacts), members);
    }
    // Counted as the estimator family counts: frames with a foot down and the
    // ZMP defined, outside by more than kFamilyThreshold_m (1 cm).
    const std::vector<AnalysisOptions> one{analysis};
    const MemberVerdict b = family_verdict({before}, one).members.front();
    r.frames_outside_before = b.outside;
    r.frames_outside_after = family_verdict({after}, one).members.front().outside;
    r.supported_frames = b.supported;
    if (!family_after.members.empty()) {
      const MemberVerdict& w = family_after.members[family_after.worst];
      r.worst_member_outside_after = w.outside;
      r.worst_member_cutoff_hz = w.cutoff_hz;
      r.worst_member_full = w.full;
      r.balanced = family_after.balanced();
    }
  } catch (const std::exception& e) {  // an allocation failure on an absurd clip: refuse, keep the input
    r = BalanceStageResult{};
    r.motion = motion;
    r.error = std::string("balance stage: ") + e.what();
  }
  return r;
}

}  // namespace tonus::balance
