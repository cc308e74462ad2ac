// Readers for the surface-EMG recordings under shared/data/emg (SOURCES.md):
//   - BioSPPy / OpenSignals "Simple Text Format": '#' header lines (the
//     sampling rate in "# Sampling Rate (Hz):= 1000.00"), then one 12-bit ADC
//     code per line; one channel.
//   - myo-readings-dataset: "ch1,...,ch8,label" per line, signed 8-bit codes,
//     about 200 Hz (the Myo's EMG rate; the file carries no timestamps).
// A one-channel recording is replicated onto all 8 channels so that every pair
// of the band sees it. Hosted code (sim and tests), not part of the firmware.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "tonus/firmware/capacity.hpp"
#include "tonus/firmware/front_end.hpp"

namespace tonus::sim {

using Frame = std::array<std::int16_t, fw::kChannels>;

struct Recording {
  std::string format;  // "biosppy" or "myo"
  float sample_rate_hz = 0.0F;
  std::size_t source_channels = 0;
  std::vector<Frame> frames;
  std::vector<int> labels;  // one per frame (myo), empty otherwise
  fw::FrontEnd front_end{};
};

// Myo EMG rate: the dataset has no timestamps; the Myo streams raw EMG at 200 Hz.
inline constexpr float kMyoRateHz = 200.0F;

// Loads a recording, detecting the format from its first line. On failure
// returns false and a message naming the file and line.
bool load_recording(const std::string& path, Recording& out, std::string& error);

}  // namespace tonus::sim
