// Stiffness levels from normalised envelopes.
//
// Per antagonist pair (channel 2p flexor, 2p+1 extensor) a co-contraction
// measure c in 0..1 (documented choice, selectable):
//   min_normalised: c = min(f, e)  - the activation both muscles share; the
//                   common part of the "co-contraction area" of Falconer &
//                   Winter (1985). Default: zero for any one-sided effort.
//   cci:            c = (lo / hi) * (lo + hi) / 2 - Rudolph et al. (2000),
//                   halved so that both at reference gives 1.
// then divided by the pair's co-contraction reference (calibration), mapped
// through a dead band d and a curve (linear, or power u^k) to 16 bits, and
// held by a hysteresis h: the level moves only when the target differs by at
// least h (or reaches 0 or full scale), so noise smaller than h cannot make
// it chatter. Groups take the maximum of the pairs mapped to them: the
// stiffest demand on a limb wins.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "tonus/firmware/capacity.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::fw {

struct LevelModel {
  proto::CoContractionMeasure measure = proto::CoContractionMeasure::min_normalised;
  float dead_band = 0.0F;  // in 0..1
  std::uint16_t hysteresis = 0;
  proto::LevelCurve curve = proto::LevelCurve::linear;
  float exponent = 1.0F;
  std::array<std::uint8_t, kPairs> pair_group{};
};

LevelModel design_levels(const proto::DeviceConfig& cfg);

float cocontraction(proto::CoContractionMeasure measure, float flexor, float extensor);

// Target level of a co-contraction c (already divided by its reference), before hysteresis.
std::uint16_t level_target(const LevelModel& m, float c);

struct LevelState {
  std::array<std::uint16_t, kPairs> pair_level{};
};

// Updates pair levels from their co-contraction (divided by reference) and
// fills the group levels.
void levels_step(const LevelModel& m, LevelState& s, std::span<const float, kPairs> c,
                 std::span<std::uint16_t, kGroups> groups);

}  // namespace tonus::fw
