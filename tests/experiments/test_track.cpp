// track: real clips as the reference. Both feedforward variants follow them
// closer than PD only, without a reset; variant (a) within a degree on walks.
#include <doctest/doctest.h>

#include <filesystem>

#include "experiments/reports.hpp"
#include "experiments/scene.hpp"
#include "experiments/track.hpp"
#include "support/sanitized.hpp"

using namespace tonus::experiments;
using tonus::avatar::Feedforward;

TEST_CASE("track: the bundled CMU walk and a Bandai Namco walk, three variants" *
          tonus::test::heavy_under_sanitizers()) {
  std::string err;
  const auto m = humanoid_model(err);
  REQUIRE(m);
  TrackOptions opt;
  opt.clips.emplace_back(TONUS_SOURCE_DIR "/tests/data/cmu_02_walk.bvh");
  const std::string bandai = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_walk_normal_001.bvh";
  if (std::filesystem::exists(bandai)) opt.clips.push_back(bandai);
  opt.max_seconds = 2.5;
  const TrackResult r = run_track(*m, opt);
  REQUIRE(r.error.empty());
  REQUIRE(r.clips.size() == opt.clips.size());
  for (const ClipTrack& c : r.clips) {
    INFO(c.clip);
    REQUIRE(c.variants.size() == 3);
    const VariantTrack& a = c.variants[0];
    const VariantTrack& b = c.variants[1];
    const VariantTrack& n = c.variants[2];
    REQUIRE(a.variant == Feedforward::simulation);
    REQUIRE(b.variant == Feedforward::inverse_dynamics);
    MESSAGE("RMS deg: simulation " << a.rms_all_rad * 57.3 << ", inverse dynamics " << b.rms_all_rad * 57.3 << ", none "
                                   << n.rms_all_rad * 57.3);
    CHECK(a.rms_all_rad < 1.0 * M_PI / 180.0);
    CHECK(a.hand_rms_m < 0.005);
    CHECK(b.rms_all_rad < 2.0 * M_PI / 180.0);
    CHECK(n.rms_all_rad > 3.0 * a.rms_all_rad);  // PD only at the same gains lags visibly
    CHECK(a.resets + b.resets + n.resets == 0);
    CHECK(b.lag_s > 0.0);
  }
  for (const Goal& g : track_goals(r)) CHECK_MESSAGE(g.met, g.what);
}
