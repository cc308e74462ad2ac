// HAL: the EMG sampler. On the band a timer triggers the ADC to scan all
// channels at the sample rate and DMA writes frames into a double buffer;
// each completed half is one SampleBlock. The core acquires a block, processes
// it and releases it. A half that the DMA overwrites before release is lost:
// the sampler never hands it out and its sequence number is skipped.
#pragma once

#include <array>
#include <cstdint>

#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/front_end.hpp"

namespace tonus::hal {

struct SampleBlock {
  std::uint32_t sequence = 0;         // +1 per block the sampler completed; gaps are lost blocks
  std::uint64_t first_sample_us = 0;  // capture time of frame 0 on the HAL clock
  std::uint16_t frames = 0;           // 1..kMaxBlockFrames
  // Frame-major raw ADC codes: samples[f * kChannels + ch].
  std::array<std::int16_t, fw::kMaxBlockFrames * fw::kChannels> samples{};
};

class EmgSampler {
 public:
  [[nodiscard]] virtual fw::FrontEnd front_end() const = 0;
  // (Re)starts sampling at rate_hz (one the front end supports); false on failure.
  virtual bool start(std::uint16_t rate_hz) = 0;
  // The oldest completed, unreleased block, or nullptr. Valid until release().
  virtual const SampleBlock* acquire() = 0;
  virtual void release() = 0;

 protected:
  ~EmgSampler() = default;
};

}  // namespace tonus::hal
