// Co-contraction measure, dead band, curve, hysteresis and grouping.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "tonus/firmware/levels.hpp"

using namespace tonus;
using namespace tonus::fw;

TEST_CASE("co-contraction measures") {
  using M = proto::CoContractionMeasure;
  CHECK(cocontraction(M::min_normalised, 0.8F, 0.3F) == doctest::Approx(0.3F));
  CHECK(cocontraction(M::min_normalised, 0.0F, 1.0F) == 0.0F);  // one-sided effort: no stiffness
  CHECK(cocontraction(M::cci, 1.0F, 1.0F) == doctest::Approx(1.0F));
  CHECK(cocontraction(M::cci, 0.5F, 0.25F) == doctest::Approx(0.5F * 0.75F * 0.5F));  // (lo/hi)(lo+hi)/2
  CHECK(cocontraction(M::cci, 0.0F, 0.0F) == 0.0F);
}

TEST_CASE("level target: dead band, full scale, curve, NaN") {
  proto::DeviceConfig cfg{};
  cfg.dead_band = 6554;  // 10 %
  LevelModel m = design_levels(cfg);
  CHECK(level_target(m, 0.05F) == 0);
  CHECK(level_target(m, 0.1F) == 0);
  CHECK(level_target(m, 1.0F) == proto::kLevelMax);
  CHECK(level_target(m, 3.0F) == proto::kLevelMax);
  CHECK(level_target(m, 0.55F) == doctest::Approx(32768).epsilon(0.001));
  CHECK(level_target(m, std::numeric_limits<float>::quiet_NaN()) == 0);
  cfg.curve = proto::LevelCurve::power;
  cfg.curve_exponent_milli = 2000;
  m = design_levels(cfg);
  CHECK(level_target(m, 0.55F) == doctest::Approx(65535 * 0.25).epsilon(0.001));
}

TEST_CASE("a scripted co-contraction ramp gives a monotonic level without chatter") {
  proto::DeviceConfig cfg{};
  const LevelModel m = design_levels(cfg);
  LevelState s;
  std::array<std::uint16_t, kGroups> groups{};
  std::uint16_t last = 0;
  int changes = 0;
  // Rising ramp with noise of +-0.4 % of full scale (below the 1 % hysteresis).
  std::uint32_t rng = 12345;
  for (int k = 0; k <= 10000; ++k) {
    rng = rng * 1664525U + 1013904223U;
    const float noise = (static_cast<float>(rng >> 8U) / 16777216.0F - 0.5F) * 0.008F;
    const float c = static_cast<float>(k) / 10000.0F + noise;
    const std::array<float, kPairs> pairs{c, c, c, c};
    levels_step(m, s, pairs, groups);
    CHECK(groups[0] >= last);  // never steps back on a rising input
    if (groups[0] != last) ++changes;
    last = groups[0];
  }
  CHECK(last == proto::kLevelMax);
  // At most one step per hysteresis width across the range (no chatter).
  CHECK(changes <= 65535 / cfg.hysteresis + 2);
  CHECK(changes > 50);
  // Holding a constant noisy input leaves the level still.
  const std::uint16_t held = [&] {
    const std::array<float, kPairs> c{0.5F, 0.5F, 0.5F, 0.5F};
    levels_step(m, s, c, groups);
    return groups[0];
  }();
  for (int k = 0; k < 1000; ++k) {
    const float c = 0.5F + ((k % 2) != 0 ? 0.004F : -0.004F);
    const std::array<float, kPairs> pairs{c, c, c, c};
    levels_step(m, s, pairs, groups);
    CHECK(groups[0] == held);
  }
}

TEST_CASE("groups take the maximum of their pairs, unused pairs feed nothing") {
  proto::DeviceConfig cfg{};
  cfg.hysteresis = 0;
  cfg.dead_band = 0;
  cfg.pair_group = {
      0, 0, 2, proto::kPairUnused, proto::kPairUnused, proto::kPairUnused, proto::kPairUnused, proto::kPairUnused};
  const LevelModel m = design_levels(cfg);
  LevelState s;
  std::array<std::uint16_t, kGroups> g{};
  const std::array<float, kPairs> c{0.2F, 0.6F, 0.4F, 1.0F};
  levels_step(m, s, c, g);
  CHECK(g[0] == level_target(m, 0.6F));
  CHECK(g[1] == 0);
  CHECK(g[2] == level_target(m, 0.4F));
  CHECK(g[3] == 0);
}
