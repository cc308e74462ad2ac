// The balance filter as a stage on a reference clip (tonusd's
// tracker.balance): off, offline (the whole clip corrected at once by the
// robust filter, `tonus zmp --correction waist`: lean, yaw and pelvis shift,
// a margin inside under every estimator of the family) or online (the
// streaming filter, whose output never depends on more than its look-ahead,
// so a clip streamed through it at load is what a live source would have
// given).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "tonus/host/balance/analysis.hpp"
#include "tonus/host/balance/online_filter.hpp"

namespace tonus::balance {

enum class BalanceMode : std::uint8_t { off, offline, online };

// "off", "offline", "online": the words tonusd's config reads.
std::string_view to_string(BalanceMode mode);

struct BalanceStageOptions {
  BalanceMode mode = BalanceMode::off;
  double lookahead_s = kMaxLookahead_s;  // online only: (0, 0.25] s
  AnalysisOptions analysis;              // the body and the estimator the filters aim with
};

struct BalanceStageResult {
  HumanMotion motion;  // corrected (off: the input)
  // Supported frames with the ZMP outside the support polygon by more than
  // 1 cm, under the analysis options' estimator, before and after, counted as
  // family_verdict counts (off: not analysed, all zero).
  std::size_t frames_outside_before = 0;
  std::size_t frames_outside_after = 0;
  std::size_t supported_frames = 0;
  // The same count under the estimator family's worst member after (family.hpp),
  // the figure the robust filter answers to; `balanced`: within the family's
  // allowed share under every member.
  std::size_t worst_member_outside_after = 0;
  double worst_member_cutoff_hz = 0.0;
  bool worst_member_full = false;
  bool balanced = false;
  std::size_t lookahead_frames = 0;  // online: the frames each output waits for
  std::string error;                 // non-empty: the stage refused (the motion is then the input)
  [[nodiscard]] bool ok() const { return error.empty(); }
};

BalanceStageResult balance_stage(const HumanMotion& motion, const BalanceStageOptions& options);

}  // namespace tonus::balance
