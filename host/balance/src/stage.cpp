#include "tonus/host/balance/stage.hpp"

#include <exception>

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

bool parse_balance_mode(std::string_view text, BalanceMode& mode) {
  for (const BalanceMode m : {BalanceMode::off, BalanceMode::offline, BalanceMode::online}) {
    if (text == to_string(m)) {
      mode = m;
      return true;
    }
  }
  return false;
}

namespace {

std::size_t supported(const Analysis& a) {
  return a.summary.frames - a.summary.frames_airborne - a.summary.frames_undefined;
}

}  // namespace

BalanceStageResult balance_stage(const HumanMotion& motion, const BalanceStageOptions& options) {
  BalanceStageResult r;
  r.motion = motion;
  if (options.mode == BalanceMode::off) return r;
  try {
    const AnalysisOptions& analysis = options.analysis;
    if (options.mode == BalanceMode::offline) {
      FilterOptions fo;
      fo.analysis = analysis;
      FilterResult f = balance_filter(motion, fo);
      if (!f.ok()) {
        r.error = "offline balance filter: " + f.error;
        return r;
      }
      r.motion = std::move(f.corrected);
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
    }
    AnalysisOptions counting = analysis;
    counting.tolerance_m = 0.01;
    const Analysis before = analyse(motion, counting);
    if (!before.ok()) {
      r.error = "balance analysis: " + before.error;
      r.motion = motion;
      return r;
    }
    const Analysis after = analyse(r.motion, counting, &before.contacts);
    r.frames_outside_before = before.summary.frames_outside;
    r.frames_outside_after = after.summary.frames_outside;
    r.supported_frames = supported(before);
  } catch (const std::exception& e) {  // an allocation failure on an absurd clip: refuse, keep the input
    r = BalanceStageResult{};
    r.motion = motion;
    r.error = std::string("balance stage: ") + e.what();
  }
  return r;
}

}  // namespace tonus::balance
