// The envelope the stiffness levels are computed from: fast after a change of
// effort, as smooth as the configured envelope while the effort holds.
//
// A linear filter cannot be both: its noise grows as its rise time shrinks (a
// one-pole of time constant tau has a relative noise ~ 0.75 / sqrt(2 B tau) on
// EMG of bandwidth B). Adaptive-memory estimators shorten the memory only when
// the amplitude changes (Park & Meek 1995, adaptive window; Sanger 2007,
// Bayesian filter; the 1-euro filter of Casiez et al. 2012 for pointing). Here:
//
//   slow  = the configured envelope (one-pole of |emg|, tau = envelope_tau_ms)
//   fast  = one-pole of |emg|, kLevelFastTauMs: the change detector
//   candidate: fast beyond [level / 2, 2 level] -> a mean of |emg| starts afresh
//   confirmed: after kLevelConfirmMs that mean is beyond [slow / 2, 2 slow]
//           -> the level is the running mean since the candidate (weight 1/n,
//           the minimum-variance estimate of a constant) until its memory
//           reaches the one-pole's (n = 1 / alpha), where slow takes it over.
//   not confirmed: noise; the level never left slow.
//
// In steady effort the level is the configured envelope; a change of more than
// about 3x in amplitude (rest to effort, effort to rest) shows within ~10 ms of
// its detection; smaller changes follow the configured envelope, as before.
// Model/Data split as the chain: design once, step per sample; no libm.
#pragma once

#include <cstdint>

#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr double kLevelFastTauMs = 15.0;       // detector: sees a step from rest in a few ms
inline constexpr double kLevelFastMinSamples = 10.0;  // ... but averages enough samples at low rates
inline constexpr float kLevelChangeRatio = 2.0F;      // a candidate change: fast beyond 2x or 1/2x the level
inline constexpr double kLevelConfirmMs = 10.0;       // a candidate is judged on the mean of this long
inline constexpr float kLevelConfirmRatio = 2.0F;     // ... which must be 2x or 1/2x the slow envelope
inline constexpr double kLevelHoldMs = 40.0;          // no new candidate while fast settles (~2.7 fast tau)
// Mean |x| to RMS for Gaussian noise, sqrt(pi / 2): the level path estimates the
// mean |emg| and reports it in the RMS envelope's units when that mode is set.
inline constexpr float kRmsOverMeanAbs = 1.25331414F;

struct LevelEnvelopeModel {
  float fast_alpha = 0.0F;                   // one-pole gain of the change detector
  float slow_alpha = 0.0F;                   // one-pole gain of the configured envelope
  float ratio = kLevelChangeRatio;           // candidate: fast beyond level x ratio or level / ratio
  float confirm_ratio = kLevelConfirmRatio;  // confirmed: mean since beyond slow x ratio or slow / ratio
  std::uint32_t confirm = 1;                 // samples before a candidate is judged
  std::uint32_t hold = 0;                    // samples without a new candidate
  std::uint32_t memory_max = 1;              // samples: 1 / slow_alpha, where the running mean meets the one-pole
  float scale = 1.0F;                        // output units: 1 (mean |x|) or kRmsOverMeanAbs (moving RMS mode)
};

LevelEnvelopeModel design_level_envelope(const proto::DeviceConfig& cfg);

struct LevelEnvelopeState {
  float fast = 0.0F;
  float slow = 0.0F;  // the configured envelope of |emg|
  float mean = 0.0F;  // mean |emg| since the last candidate change
  float level = 0.0F;
  std::uint32_t count = 0;  // samples in mean
  std::uint32_t hold = 0;
  bool following = false;        // a candidate change is being averaged
  bool confirmed = false;        // ... and judged real: the level is its mean
  std::uint32_t candidates = 0;  // diagnostics and tests
  std::uint32_t changes = 0;     // confirmed candidates
};

namespace detail {
inline bool beyond(float a, float b, float ratio) { return a > ratio * b || b > ratio * a; }
}  // namespace detail

// One rectified sample; returns the level envelope in the configured envelope's
// units. Inline: it runs per sample and channel inside chain_step.
inline float level_envelope_step(const LevelEnvelopeModel& m, LevelEnvelopeState& s, float rectified) {
  s.fast += m.fast_alpha * (rectified - s.fast);
  s.slow += m.slow_alpha * (rectified - s.slow);
  if (s.hold > 0) {
    --s.hold;
  } else if (detail::beyond(s.fast, s.level, m.ratio)) {
    // A candidate change of effort: average afresh from here. A change being
    // followed hands its mean over first, so the output holds while judging.
    if (s.confirmed) s.slow = s.mean;
    s.following = true;
    s.confirmed = false;
    s.count = 0;
    s.mean = 0.0F;
    s.hold = m.hold;
    ++s.candidates;
  }
  if (s.following) {
    ++s.count;
    s.mean += (rectified - s.mean) / static_cast<float>(s.count);
    if (!s.confirmed && s.count == m.confirm) {
      s.confirmed = detail::beyond(s.mean, s.slow, m.confirm_ratio);
      s.following = s.confirmed;  // else noise, not a change: the slow envelope never stopped
      if (s.confirmed) ++s.changes;
    }
    if (s.confirmed && s.count >= m.memory_max) {
      s.slow = s.mean;  // the running mean has the one-pole's memory now: hand over
      s.following = false;
      s.confirmed = false;
    }
  }
  s.level = s.confirmed ? s.mean : s.slow;
  return s.level * m.scale;
}

inline float level_envelope_value(const LevelEnvelopeModel& m, const LevelEnvelopeState& s) {
  return s.level * m.scale;
}

}  // namespace tonus::fw
