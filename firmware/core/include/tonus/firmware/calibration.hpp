// Normalisation of the envelopes and the calibration state machine that
// measures it on the performer, driven by host commands:
//   rest            -> baseline per channel: mean envelope while relaxed
//   max_contraction -> reference per channel: peak envelope during a maximal
//                      voluntary contraction (MVC, the SENIAM/De Luca norm)
//   co_contraction  -> optional per pair: peak co-contraction measure while the
//                      performer stiffens the joint as hard as is comfortable,
//                      so that this effort maps to full level
// Each phase is timed by the device on sample count (a host that disappears
// cannot leave it hanging); a phase whose samples do not arrive by its clock
// deadline times out. Abort and timeout keep the previous calibration.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/front_end.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr float kMvcOverRest = 2.0F;        // an MVC envelope must at least double the rest one
inline constexpr float kMinCoContraction = 0.05F;  // below this the co-contraction reference is noise
inline constexpr float kMinValidFraction = 0.5F;   // of a phase's samples with the electrode on
inline constexpr std::uint32_t kCalibrationGraceMs = 1000;

struct Calibration {
  std::array<float, kChannels> baseline{};    // rest envelope, ADC counts
  std::array<float, kChannels> reference{};   // MVC envelope, ADC counts
  std::array<float, kPairs> cocontraction{};  // measure at the reference effort (0..1), 1 when unset
  std::uint16_t baseline_mask = 0;            // channels with a measured baseline
  std::uint16_t reference_mask = 0;           // channels with a measured MVC
  std::uint8_t cocontraction_mask = 0;        // pairs with a measured co-contraction reference

  [[nodiscard]] std::uint16_t calibrated_mask() const {
    return static_cast<std::uint16_t>(baseline_mask & reference_mask);
  }
  friend bool operator==(const Calibration&, const Calibration&) = default;
};

Calibration default_calibration(const FrontEnd& fe);

// A reference closer to the baseline than this (ADC counts) gives no usable
// scale: such a channel reads 0 (no effort) rather than full scale.
inline constexpr float kMinSpanCounts = 1.0F;

// Envelope in units of the channel's reference (0 at baseline, 1 at MVC), >= 0.
inline float normalise(const Calibration& c, std::size_t ch, float envelope) {
  const float span = c.reference[ch] - c.baseline[ch];
  if (!(span >= kMinSpanCounts)) return 0.0F;  // also a NaN from a corrupt record
  const float v = (envelope - c.baseline[ch]) / span;
  return v > 0.0F ? v : 0.0F;
}

class Calibrator {
 public:
  // Starts a phase. Status::wrong_state while one runs, bad_value for a mask
  // naming no channel (or no whole pair for the co-contraction phase).
  proto::Status start(const proto::CalibrationStart& req, float sample_rate_hz, std::uint64_t now_us);
  proto::Status abort();

  // One frame of envelopes (ADC counts), the channels flagged off, and the
  // co-contraction measure per pair (used by the co_contraction phase).
  // Writes the result into `live` when the phase completes.
  void on_frame(std::span<const float, kChannels> envelopes, std::uint16_t off_mask,
                std::span<const float, kPairs> cocontraction, Calibration& live);
  // Clock check: a phase past its deadline times out.
  void on_tick(std::uint64_t now_us);

  [[nodiscard]] bool running() const { return state_ == proto::CalibrationState::running; }
  [[nodiscard]] proto::CalibrationStatus status(const Calibration& live) const;
  // True once after each phase that changed `live` (the config becomes dirty).
  bool take_changed() {
    const bool c = changed_;
    changed_ = false;
    return c;
  }

 private:
  void finish(Calibration& live);

  proto::CalibrationState state_ = proto::CalibrationState::idle;
  proto::CalibrationPhase phase_ = proto::CalibrationPhase::rest;
  bool any_phase_ = false;
  std::uint8_t phases_done_ = 0;
  std::uint16_t mask_ = 0;
  std::uint32_t needed_ = 0;
  std::uint32_t seen_ = 0;
  std::uint64_t deadline_us_ = 0;
  bool changed_ = false;
  std::array<double, kChannels> sum_{};
  std::array<float, kChannels> peak_{};
  std::array<std::uint32_t, kChannels> valid_{};
  std::array<float, kPairs> pair_peak_{};
  std::array<std::uint32_t, kPairs> pair_valid_{};
};

}  // namespace tonus::fw
