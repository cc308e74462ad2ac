// The level envelope (level_envelope.hpp) on deterministic rectified inputs,
// checked against closed forms computed here in double precision.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>

#include "tonus/firmware/device.hpp"
#include "tonus/firmware/level_envelope.hpp"

using namespace tonus;
using namespace tonus::fw;

namespace {

proto::DeviceConfig config_at(std::uint16_t rate, std::uint16_t tau_ms = 100) {
  FrontEnd fe;
  fe.min_rate_hz = rate;
  fe.max_rate_hz = rate;
  fe.rate_step_hz = 0;
  proto::DeviceConfig cfg = default_config(fe);
  cfg.envelope_tau_ms = tau_ms;
  return cfg;
}

// A state settled on a constant rectified input x (no change being followed).
LevelEnvelopeState settled(float x) {
  LevelEnvelopeState s;
  s.fast = x;
  s.slow = x;
  s.level = x;
  return s;
}

}  // namespace

TEST_CASE("level envelope design: detector and memory from the configuration") {
  const LevelEnvelopeModel m = design_level_envelope(config_at(2000));
  // alpha = 1 - exp(-1 / (tau fs)) with tau 15 ms (detector) and 100 ms (configured).
  CHECK(m.fast_alpha == doctest::Approx(1.0 - std::exp(-1.0 / 30.0)));
  CHECK(m.slow_alpha == doctest::Approx(1.0 - std::exp(-1.0 / 200.0)));
  CHECK(m.memory_max == 200);  // the running mean meets the one-pole at n = 1 / alpha
  CHECK(m.confirm == 20);      // 10 ms
  CHECK(m.hold == 80);         // 40 ms
  CHECK(m.scale == 1.0F);
  // At 200 Hz the detector averages 10 samples (50 ms), never fewer.
  const LevelEnvelopeModel slow_rate = design_level_envelope(config_at(200));
  CHECK(slow_rate.fast_alpha == doctest::Approx(1.0 - std::exp(-1.0 / 10.0)));
  // Never slower than the configured envelope itself.
  const LevelEnvelopeModel short_tau = design_level_envelope(config_at(2000, 5));
  CHECK(short_tau.fast_alpha == doctest::Approx(short_tau.slow_alpha));
  proto::DeviceConfig rms = config_at(2000);
  rms.envelope_mode = proto::EnvelopeMode::moving_rms;
  CHECK(design_level_envelope(rms).scale == doctest::Approx(std::sqrt(std::acos(-1.0) / 2.0)));
}

TEST_CASE("a step of effort: the level is the one-pole until the change is confirmed, then the mean since it") {
  const LevelEnvelopeModel m = design_level_envelope(config_at(2000));
  LevelEnvelopeState s = settled(1.0F);
  const double af = m.fast_alpha, as = m.slow_alpha;
  // Closed forms after a step 1 -> 10 at n = 0 (n samples in): fast = 10 - 9 (1 - af)^n,
  // slow = 10 - 9 (1 - as)^n. The candidate is the first n with fast > 2 slow.
  int candidate = -1;
  for (int n = 1; n < 1000 && candidate < 0; ++n) {
    if (10.0 - 9.0 * std::pow(1.0 - af, n) > 2.0 * (10.0 - 9.0 * std::pow(1.0 - as, n))) candidate = n;
  }
  REQUIRE(candidate > 0);
  MESSAGE("candidate after " << candidate << " samples, confirmed " << m.confirm - 1 << " samples later");
  int confirmed_at = -1;
  for (int n = 1; n <= 400; ++n) {
    const float level = level_envelope_step(m, s, 10.0F);
    if (confirmed_at < 0 && s.confirmed) confirmed_at = n;
    if (confirmed_at < 0) {
      INFO("n = " << n);
      CHECK(static_cast<double>(level) == doctest::Approx(10.0 - 9.0 * std::pow(1.0 - as, n)).epsilon(1e-5));
    } else {
      CHECK(level == 10.0F);  // the mean of samples that are all 10
    }
  }
  // Float against double may move the threshold crossing by a sample.
  CHECK(std::abs(confirmed_at - (candidate + static_cast<int>(m.confirm) - 1)) <= 1);
  CHECK(s.changes == 1);
  // After memory_max samples of the mean, the one-pole takes over from it.
  CHECK_FALSE(s.following);
  CHECK(s.slow == 10.0F);

  // And back to rest: the same, downwards.
  int down = -1;
  for (int n = 1; n <= 400; ++n) {
    const float level = level_envelope_step(m, s, 1.0F);
    if (down < 0 && s.confirmed) down = n;
    if (down > 0) CHECK(level == 1.0F);
  }
  // fast = 1 + 9 (1 - af)^n falls below slow / 2 = (1 + 9 (1 - as)^n) / 2; confirmed confirm - 1 later.
  int fall = -1;
  for (int n = 1; n < 1000 && fall < 0; ++n) {
    if (2.0 * (1.0 + 9.0 * std::pow(1.0 - af, n)) < 1.0 + 9.0 * std::pow(1.0 - as, n)) fall = n;
  }
  REQUIRE(fall > 0);
  CHECK(std::abs(down - (fall + static_cast<int>(m.confirm) - 1)) <= 1);
  CHECK(s.changes == 2);
}

TEST_CASE("a short burst that the mean does not confirm leaves the configured envelope untouched") {
  const LevelEnvelopeModel m = design_level_envelope(config_at(2000));
  LevelEnvelopeState s = settled(1.0F);
  float reference = 1.0F;  // the configured one-pole, computed apart with the same expression
  for (int n = 0; n < 400; ++n) {
    const float x = n >= 100 && n < 110 ? 8.0F : 1.0F;  // 5 ms at 8x: fast crosses 2x, the 10 ms mean does not
    reference += m.slow_alpha * (x - reference);
    const float level = level_envelope_step(m, s, x);
    CHECK(level == reference);
  }
  CHECK(s.candidates == 1);
  CHECK(s.changes == 0);
}

TEST_CASE("a constant input from power-up: no start-up ramp once confirmed") {
  const LevelEnvelopeModel m = design_level_envelope(config_at(2000));
  LevelEnvelopeState s;
  float level = 0.0F;
  for (std::uint32_t n = 0; n < m.confirm; ++n) level = level_envelope_step(m, s, 3.0F);
  CHECK(level == 3.0F);
  CHECK(s.changes == 1);
}
