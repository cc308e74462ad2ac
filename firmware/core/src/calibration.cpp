#include "tonus/firmware/calibration.hpp"

namespace tonus::fw {

namespace {

constexpr std::uint16_t kAllChannels = static_cast<std::uint16_t>((1U << kChannels) - 1U);

bool has(std::uint16_t mask, std::size_t ch) { return ((static_cast<unsigned>(mask) >> ch) & 1U) != 0; }

std::uint16_t whole_pairs(std::uint16_t mask) {
  std::uint16_t out = 0;
  for (std::size_t p = 0; p < kPairs; ++p) {
    if (has(mask, 2 * p) && has(mask, 2 * p + 1)) out = static_cast<std::uint16_t>(out | (1U << p));
  }
  return out;
}

}  // namespace

Calibration default_calibration(const FrontEnd& fe) {
  Calibration c;
  c.baseline.fill(0.0F);
  c.reference.fill(fe.default_reference);
  c.cocontraction.fill(1.0F);
  return c;
}

proto::Status Calibrator::start(const proto::CalibrationStart& req, float sample_rate_hz, std::uint64_t now_us) {
  if (running()) return proto::Status::wrong_state;
  const auto mask = static_cast<std::uint16_t>(req.channel_mask & kAllChannels);
  if (mask == 0) return proto::Status::bad_value;
  if (req.phase == proto::CalibrationPhase::co_contraction && whole_pairs(mask) == 0) return proto::Status::bad_value;
  if (req.duration_ms < proto::CalibrationStart::kMinDurationMs ||
      req.duration_ms > proto::CalibrationStart::kMaxDurationMs) {
    return proto::Status::bad_value;
  }
  state_ = proto::CalibrationState::running;
  phase_ = req.phase;
  any_phase_ = true;
  mask_ = mask;
  needed_ = static_cast<std::uint32_t>(static_cast<float>(req.duration_ms) * sample_rate_hz / 1000.0F);
  if (needed_ == 0) needed_ = 1;
  seen_ = 0;
  deadline_us_ = now_us + (static_cast<std::uint64_t>(req.duration_ms) + kCalibrationGraceMs) * 1000U;
  sum_.fill(0.0);
  peak_.fill(0.0F);
  valid_.fill(0);
  pair_peak_.fill(0.0F);
  pair_valid_.fill(0);
  return proto::Status::ok;
}

proto::Status Calibrator::abort() {
  if (!running()) return proto::Status::wrong_state;
  state_ = proto::CalibrationState::aborted;
  return proto::Status::ok;
}

void Calibrator::on_frame(std::span<const float, kChannels> envelopes, std::uint16_t off_mask,
                          std::span<const float, kPairs> cocontraction, Calibration& live) {
  if (!running()) return;
  for (std::size_t ch = 0; ch < kChannels; ++ch) {
    if (!has(mask_, ch) || has(off_mask, ch)) continue;
    sum_[ch] += static_cast<double>(envelopes[ch]);
    if (envelopes[ch] > peak_[ch]) peak_[ch] = envelopes[ch];
    ++valid_[ch];
  }
  for (std::size_t p = 0; p < kPairs; ++p) {
    if (has(off_mask, 2 * p) || has(off_mask, 2 * p + 1)) continue;
    if (cocontraction[p] > pair_peak_[p]) pair_peak_[p] = cocontraction[p];
    ++pair_valid_[p];
  }
  if (++seen_ >= needed_) finish(live);
}

void Calibrator::on_tick(std::uint64_t now_us) {
  if (running() && now_us > deadline_us_) state_ = proto::CalibrationState::timed_out;
}

void Calibrator::finish(Calibration& live) {
  const auto min_valid = static_cast<std::uint32_t>(kMinValidFraction * static_cast<float>(needed_));
  Calibration next = live;
  bool any = false;
  if (phase_ == proto::CalibrationPhase::co_contraction) {
    const std::uint16_t pairs = whole_pairs(mask_);
    for (std::size_t p = 0; p < kPairs; ++p) {
      if (!has(pairs, p) || pair_valid_[p] < min_valid || pair_peak_[p] < kMinCoContraction) continue;
      next.cocontraction[p] = pair_peak_[p];
      next.cocontraction_mask = static_cast<std::uint8_t>(next.cocontraction_mask | (1U << p));
      any = true;
    }
  } else {
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      if (!has(mask_, ch) || valid_[ch] < min_valid) continue;
      const auto bit = static_cast<std::uint16_t>(1U << ch);
      if (phase_ == proto::CalibrationPhase::rest) {
        next.baseline[ch] = static_cast<float>(sum_[ch] / valid_[ch]);
        next.baseline_mask = static_cast<std::uint16_t>(next.baseline_mask | bit);
        // A new baseline invalidates an MVC that no longer clears it; the
        // reference is then raised to the least an MVC could be, so the
        // channel keeps a sane scale (not a span near zero) until one is measured.
        if (next.reference[ch] < kMvcOverRest * next.baseline[ch]) {
          next.reference_mask = static_cast<std::uint16_t>(next.reference_mask & ~bit);
          next.reference[ch] = kMvcOverRest * next.baseline[ch] + kMinSpanCounts;
        }
        any = true;
      } else if (peak_[ch] >= kMvcOverRest * next.baseline[ch] && peak_[ch] > next.baseline[ch] + 1.0F) {
        next.reference[ch] = peak_[ch];
        next.reference_mask = static_cast<std::uint16_t>(next.reference_mask | bit);
        any = true;
      }
    }
  }
  if (any) {
    live = next;
    changed_ = true;
    phases_done_ = static_cast<std::uint8_t>(phases_done_ | (1U << (static_cast<unsigned>(phase_) - 1U)));
    state_ = proto::CalibrationState::done;
  } else {
    state_ = proto::CalibrationState::failed;
  }
}

proto::CalibrationStatus Calibrator::status(const Calibration& live) const {
  proto::CalibrationStatus s;
  s.state = state_;
  s.phase = any_phase_ ? static_cast<std::uint8_t>(phase_) : 0;
  if (running()) {
    s.progress_pct = static_cast<std::uint8_t>(static_cast<std::uint64_t>(seen_) * 100U / needed_);
  } else {
    s.progress_pct = state_ == proto::CalibrationState::done ? 100 : 0;
  }
  s.calibrated_mask = live.calibrated_mask();
  s.phases_done = phases_done_;
  return s;
}

}  // namespace tonus::fw
