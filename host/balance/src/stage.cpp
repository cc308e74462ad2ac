#include "tonus/host/balance/stage.hpp"

#include <exception>
#include <vector>

#include "tonus/host/balance/family.hpp"
#include "tonus/host/balance/filter.hpp"

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
    if (options.mode == BalanceMode::offline) {
      FilterOptions fo;
      fo.analysis = analysis;
      FilterResult f = balance_filter(motion, fo);
      if (!f.ok()) {
        r.error = "offline balance filter: " + f.error;
        return r;
      }
      r.motion = std::move(f.corrected);
      before = std::move(f.before);  // the filter analysed both already
      after = std::move(f.after);
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
    }
    // Counted as the estimator family counts: frames with a foot down and the
    // ZMP defined, outside by more than kFamilyThreshold_m (1 cm).
    const std::vector<AnalysisOptions> one{analysis};
    const MemberVerdict b = family_verdict({before}, one).members.front();
    r.frames_outside_before = b.outside;
    r.frames_outside_after = family_verdict({after}, one).members.front().outside;
    r.supported_frames = b.supported;
  } catch (const std::exception& e) {  // an allocation failure on an absurd clip: refuse, keep the input
    r = BalanceStageResult{};
    r.motion = motion;
    r.error = std::string("balance stage: ") + e.what();
  }
  return r;
}

}  // namespace tonus::balance
